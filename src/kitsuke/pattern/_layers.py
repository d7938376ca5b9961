"""Cloth layers of a pattern: which parts of which pieces lie over which when worn (a kimono's left front over its
right front, SPEC §5.4).

A pattern states them in its `meta["layers"]` (kept by the kitsuke JSON)::

    "layers": [{"piece": "okumi_left", "layer": 2},
               {"piece": "migoro_left", "layer": 2, "box_cm": [x0, y0, x1, y1]},   # only the faces inside the box
               {"piece": "okumi_right", "layer": 1}, ...]

Where faces of two different layers come near each other on the body, the higher layer is kept outside the lower
one (`kitsuke.cloth.keep_layers`); faces of no layer (0) are free. A face belongs to a region when its centroid, in
the piece's pattern coordinates (cm), lies in the region's box; the last region that takes a face wins.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import InputError

#: Highest layer number (`kitsuke.cloth.ClothModel` keeps a vertex's layers as bits of an int64).
MAX_LAYER = 62


@dataclass(frozen=True)
class LayerRegion:
    """A part of a piece on one cloth layer.

    piece : the piece's name. layer : 1..62, higher lies outside lower.
    box_cm : (x0, y0, x1, y1) in the piece's pattern coordinates, cm, or None for the whole piece.
    """

    piece: str
    layer: int
    box_cm: tuple[float, float, float, float] | None = None

    def to_dict(self) -> dict:
        d: dict = {"piece": self.piece, "layer": self.layer}
        if self.box_cm is not None:
            d["box_cm"] = list(self.box_cm)
        return d


def pattern_layers(meta: dict, piece_names: list[str]) -> tuple[LayerRegion, ...]:
    """The layer regions of a pattern's `meta["layers"]` (none without it). Raises InputError for a malformed
    entry or one naming a piece the pattern lacks."""
    raw = meta.get("layers") if isinstance(meta, dict) else None
    if raw is None:
        return ()
    if not isinstance(raw, list):
        raise InputError('meta "layers" must be a list of {"piece", "layer", "box_cm"} objects')
    out = []
    for i, r in enumerate(raw):
        where = f'meta "layers" entry {i}'
        if not isinstance(r, dict) or not isinstance(r.get("piece"), str) or "layer" not in r:
            raise InputError(f'{where}: needs "piece" (a name) and "layer" (1..{MAX_LAYER})')
        if r["piece"] not in piece_names:
            raise InputError(f"{where}: no piece named {r['piece']!r}")
        layer = r["layer"]
        if isinstance(layer, bool) or not isinstance(layer, int) or not 1 <= layer <= MAX_LAYER:
            raise InputError(f"{where}: layer must be an integer 1..{MAX_LAYER}, got {layer!r}")
        box = r.get("box_cm")
        if box is not None:
            ok = (
                isinstance(box, list | tuple)
                and len(box) == 4
                and all(isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v) for v in box)
            )
            if not ok or not (box[0] < box[2] and box[1] < box[3]):
                raise InputError(f"{where}: box_cm must be [x0, y0, x1, y1] cm with x0 < x1 and y0 < y1, got {box!r}")
            box = tuple(float(v) for v in box)
        out.append(LayerRegion(r["piece"], layer, box))
    return tuple(out)


def face_layers(
    regions: tuple[LayerRegion, ...] | list[LayerRegion],
    piece_names: list[str],
    piece_faces: np.ndarray,
    corners_cm: np.ndarray,
) -> np.ndarray | None:
    """(F,) int8 layer of every face (0: none), or None when there are no regions.

    piece_faces : (P, 2) [start, stop) face range of each piece. corners_cm : (F, 3, 2) pattern positions of the
    faces' corners, cm, in their piece's coordinates.
    """
    if not regions:
        return None
    centroid = np.asarray(corners_cm, dtype=np.float64).mean(axis=1)
    layer = np.zeros(len(centroid), dtype=np.int8)
    for r in regions:
        a, b = piece_faces[piece_names.index(r.piece)]
        inside = np.ones(b - a, dtype=bool)
        if r.box_cm is not None:
            x, y = centroid[a:b, 0], centroid[a:b, 1]
            x0, y0, x1, y1 = r.box_cm
            inside = (x >= x0) & (x <= x1) & (y >= y0) & (y <= y1)
        layer[a:b][inside] = r.layer
    return layer
