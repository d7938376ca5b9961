"""Outputs of a dressed garment (SPEC §3.3): the checkable OBJ, a GLB for viewers, the JSON report, PNG views.

OBJ: `v` world positions (metres); `vt` = each corner's pattern position in metres, piece-local, not normalised (so
rest lengths can be recovered); `f v/vt`; seam vertices shared (one `v`, a `vt` per side); one comment line
`# kitsuke piece <name> <first_face> <last_face>` per piece (faces counted from 0, last included); for layered cloth
(a kimono's fronts) one line `# kitsuke layer <layer> <first_face> <last_face>` per run of faces on a layer above 0;
`# kitsuke contact_offset_m <metres>`: how far off the body the garment was dressed (a kimono lies 3 mm off, over its
under-kimonos), so that a drag or re-wrap of the file keeps it there.
GLB: the same surface split where its UVs differ, UVs normalised to the texture tile, double-sided material,
optionally the body as a second mesh.
"""

from __future__ import annotations

import io
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._files import write_json_atomic, write_text_atomic
from ..cloth._model import MAX_LAYER
from ..errors import InputError
from ..geometry import TriMesh, save_mesh
from .wrap import DressedGarment

PIECE_TAG = "kitsuke piece"
LAYER_TAG = "kitsuke layer"
NAME_TAG = "kitsuke dressed garment"
OFFSET_TAG = "kitsuke contact_offset_m"
#: The largest contact offset a garment file may give, metres (cloth 5 cm off the body is not dressed on it).
MAX_OFFSET_M = 0.05


@dataclass
class GarmentFile:
    """A dressed garment read back from its OBJ (enough to carry on: drag, re-wrap, measure).

    positions : (V, 3) float64 m. faces : (F, 3) int64. corner_uv : (F, 3, 2) float64, pattern metres.
    piece_names : (P,) names. piece_faces : (P, 2) int64 [start, stop) face ranges.
    name : the garment's name (from the file's `# kitsuke dressed garment <name>` line; "garment" without one).
    face_layer : (F,) int8 cloth layer of each face (`kitsuke.cloth.ClothModel.face_layer`), or None.
    contact_offset_m : metres off the body it was dressed at (`ClothParams.contact_offset_m`), or None (not said).
    rest_corners : (F, 3, 2) float64 metres, the cloth's rest shape where it is not the pattern's (a gathered
        seam: `DressedGarment.gathers`), or None: corner_uv is the rest shape. Not written to the OBJ, whose vt
        stay the pattern's (a garment read back is measured ungathered).
    The writers below take a GarmentFile as well as a DressedGarment (a dragged garment is written this way).
    """

    positions: np.ndarray
    faces: np.ndarray
    corner_uv: np.ndarray
    piece_names: list[str]
    piece_faces: np.ndarray
    name: str = "garment"
    face_layer: np.ndarray | None = None
    contact_offset_m: float | None = None
    rest_corners: np.ndarray | None = None

    @property
    def rest_shape(self) -> np.ndarray:
        """(F, 3, 2) float64 metres: the corners a cloth model of this garment rests at."""
        return self.corner_uv if self.rest_corners is None else self.rest_corners

    @property
    def rest_edge_lengths(self) -> np.ndarray:
        """(F, 3) float64 metres: rest length of each face's edges (0-1, 1-2, 2-0) of its rest shape."""
        uv = self.rest_shape
        return np.linalg.norm(uv[:, [1, 2, 0]] - uv, axis=2)


def garment_obj_text(garment: DressedGarment | GarmentFile) -> str:
    """The SPEC §3.3 OBJ of a dressed garment, as text."""
    out = io.StringIO()
    out.write(f"# {NAME_TAG} {garment.name}\n# v: world metres (Y up); vt: pattern metres, piece-local\n")
    for name, (a, b) in zip(garment.piece_names, garment.piece_faces, strict=True):
        out.write(f"# {PIECE_TAG} {name} {int(a)} {int(b) - 1}\n")
    layer = _face_layer(garment)
    if layer is not None:
        cut = np.flatnonzero(np.diff(layer)) + 1
        for a, b in zip(np.r_[0, cut], np.r_[cut, len(layer)], strict=True):
            if layer[a]:
                out.write(f"# {LAYER_TAG} {int(layer[a])} {int(a)} {int(b) - 1}\n")
    offset = garment.model.params.contact_offset_m if isinstance(garment, DressedGarment) else garment.contact_offset_m
    if offset is not None:
        out.write(f"# {OFFSET_TAG} {offset:.6g}\n")
    np.savetxt(out, garment.positions, fmt="v %.7f %.7f %.7f")
    np.savetxt(out, garment.corner_uv.reshape(-1, 2), fmt="vt %.7f %.7f")
    f = garment.faces + 1
    t = np.arange(1, 3 * len(f) + 1).reshape(-1, 3)
    np.savetxt(out, np.stack([f, t], axis=2).reshape(-1, 6), fmt="f %d/%d %d/%d %d/%d")
    return out.getvalue()


def write_garment_obj(garment: DressedGarment | GarmentFile, path: str | os.PathLike[str]) -> Path:
    """Write the SPEC §3.3 OBJ atomically."""
    return write_text_atomic(path, garment_obj_text(garment))


def read_garment_obj(path: str | os.PathLike[str]) -> GarmentFile:
    """Read a dressed garment OBJ written by kitsuke (or any OBJ whose vt are pattern metres).

    Raises InputError naming the file when it has no `vt` on every corner or holds NaN.
    """
    from ..geometry.obj import read_obj

    data = read_obj(path)
    if data.uv is None or data.face_uv is None or (data.face_uv < 0).any():
        raise InputError("not a dressed garment: every face corner needs a vt (its pattern position)", path)
    if not (np.isfinite(data.vertices).all() and np.isfinite(data.uv).all()):
        raise InputError("holds NaN or infinite coordinates", path)
    names, ranges, garment_name = [], [], "garment"
    layer = np.zeros(len(data.faces), dtype=np.int8)
    offset = None
    for line in data.comments:
        if line.startswith(NAME_TAG + " ") and line[len(NAME_TAG) + 1 :].strip():
            garment_name = line[len(NAME_TAG) + 1 :].strip()
        elif line.startswith(PIECE_TAG + " "):
            try:
                name, first, last = line[len(PIECE_TAG) + 1 :].rsplit(" ", 2)
                first, last = int(first), int(last)
            except ValueError:
                raise InputError(f"bad piece line {line!r}", path) from None
            if not 0 <= first <= last < len(data.faces):
                raise InputError(f"piece line {line!r}: names faces the file does not have", path)
            names.append(name)
            ranges.append((first, last + 1))
        elif line.startswith(LAYER_TAG + " "):
            try:
                value, first, last = (int(v) for v in line[len(LAYER_TAG) + 1 :].split())
            except ValueError:
                raise InputError(f"bad layer line {line!r}", path) from None
            if not (1 <= value <= MAX_LAYER and 0 <= first <= last < len(data.faces)):
                raise InputError(f"layer line {line!r}: layer 1..{MAX_LAYER} over faces the file has", path)
            layer[first : last + 1] = value
        elif line.startswith(OFFSET_TAG + " "):
            try:
                offset = float(line[len(OFFSET_TAG) + 1 :])
            except ValueError:
                raise InputError(f"bad contact offset line {line!r}", path) from None
            if not (0 <= offset <= MAX_OFFSET_M):  # also NaN
                raise InputError(f"contact offset line {line!r}: 0 to {MAX_OFFSET_M} metres", path)
    if not names:
        names, ranges = ["garment"], [(0, len(data.faces))]
    piece_faces = np.array(ranges, dtype=np.int64)
    return GarmentFile(
        data.vertices,
        data.faces,
        data.uv[data.face_uv],
        names,
        piece_faces,
        garment_name,
        layer if layer.any() else None,
        offset,
    )


def _face_layer(garment: DressedGarment | GarmentFile) -> np.ndarray | None:
    return garment.model.face_layer if isinstance(garment, DressedGarment) else garment.face_layer


def garment_glb_mesh(
    garment: DressedGarment | GarmentFile, *, tile_m: float = 1.0, texture: np.ndarray | None = None
) -> TriMesh:
    """The garment as a TriMesh for viewers: vertices split where corners disagree on uv; uv = pattern / tile_m."""
    index, faces, uv = viewer_vertices(garment)
    return TriMesh(garment.positions[index], faces, uv / tile_m, name=garment.name, texture=texture)


def viewer_vertices(garment: DressedGarment | GarmentFile) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """How viewers see the garment: (V', ) int64 the garment vertex of each viewer vertex (split where corners
    disagree on uv: a seam), (F, 3) faces on them, (V', 2) their pattern uv in metres."""
    corner_v = garment.faces.reshape(-1)
    corner_uv = garment.corner_uv.reshape(-1, 2)
    key = np.concatenate([corner_v[:, None].astype(np.float64), np.round(corner_uv, 9)], axis=1)
    uniq, inverse = np.unique(key, axis=0, return_inverse=True)
    return uniq[:, 0].astype(np.int64), inverse.reshape(-1, 3), uniq[:, 1:]


def write_garment_glb(
    garment: DressedGarment | GarmentFile,
    path: str | os.PathLike[str],
    *,
    body: TriMesh | None = None,
    texture: np.ndarray | None = None,
    tile_m: float = 1.0,
) -> Path:
    """Write a GLB: the double-sided garment (texture repeating every `tile_m` metres of pattern) and the body."""
    meshes = [garment_glb_mesh(garment, tile_m=tile_m, texture=texture)]
    if body is not None:
        meshes.append(TriMesh(body.vertices, body.faces, name="body"))
    return save_mesh(meshes, path)


def write_garment_report(garment: DressedGarment, path: str | os.PathLike[str]) -> Path:
    """Write `garment.summary()` (counts, timings, stroke residuals, SPEC §6 quality) as JSON."""
    return write_json_atomic(path, garment.summary())


def write_garment_outputs(
    garment: DressedGarment,
    body: TriMesh,
    glb: str | os.PathLike[str] | None = None,
    obj: str | os.PathLike[str] | None = None,
    report: str | os.PathLike[str] | None = None,
    png: str | os.PathLike[str] | None = None,
) -> None:
    """A dressed garment's outputs where a path is given: the GLB with the body, the OBJ, the report, the PNG
    (what `kitsuke dress` writes, and `kitsuke batch dress` for each job)."""
    if glb:
        write_garment_glb(garment, glb, body=body)
    if obj:
        write_garment_obj(garment, obj)
    if report:
        write_garment_report(garment, report)
    if png:
        write_garment_png(garment, body, png)


def write_garment_png(
    garment: DressedGarment | GarmentFile,
    body: TriMesh,
    path: str | os.PathLike[str],
    *,
    size: tuple[int, int] = (500, 640),
) -> Path:
    """Write a labelled front / side / back sheet of the garment on the body."""
    from ..render import render_sheet, write_png

    mesh = garment_glb_mesh(garment)
    return write_png(path, render_sheet([body, TriMesh(mesh.vertices, mesh.faces, name=garment.name)], size=size))


def as_garment_file(garment: DressedGarment | GarmentFile) -> GarmentFile:
    """A DressedGarment as the GarmentFile its OBJ would read back as (positions copied); a GarmentFile as is."""
    if isinstance(garment, GarmentFile):
        return garment
    if isinstance(garment, DressedGarment):
        return GarmentFile(
            np.array(garment.positions, dtype=np.float64),
            garment.faces,
            garment.corner_uv,
            list(garment.piece_names),
            garment.piece_faces,
            garment.name,
            garment.model.face_layer,
            garment.model.params.contact_offset_m,
            garment.model.rest_corners if garment.gathers else None,
        )
    raise InputError("garment must be a DressedGarment or a GarmentFile (read_garment_obj)")
