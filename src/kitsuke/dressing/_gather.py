"""Gathered seams: a seam whose two sides differ in length gathers the longer side onto the shorter one.

That is how GarmentCode sews a stitch of unequal edges (its ruffles: a skirt gathered into a waistband, a sleeve into
a cuff, a waistband wider than the waist), and how a tailor would. Sewn as it is, the difference tears the seam
(a 10 cm waistband segment on a 6.7 cm skirt panel: 28 % strain on both sides). The cloth model instead takes the
gathered cloth's rest shape: every triangle of the longer side near the seam is shortened along the seam, by the
seams' length ratio at the seam, easing to none `depth_cm` into the piece; edges are then measured against those
lengths. A mesh cannot show gathers finer than its edges, so the cloth lies as their envelope.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..pattern import Pattern, PatternMesh
from ._weld import Welded


@dataclass(frozen=True)
class Gather:
    """One gathered seam. seam : its index in the pattern. piece : the gathered (longer) side's piece.
    ratio : shorter / longer side length (< 1). faces : garment faces whose rest shape it shortened."""

    seam: int
    piece: str
    ratio: float
    faces: int


def gathers(a_cm: float, b_cm: float, min_difference: float, min_cm: float) -> bool:
    """Whether a seam whose sides are `a_cm` and `b_cm` long gathers its longer side: they differ by more than
    `min_difference` of the longer and by more than `min_cm`."""
    longer, excess = max(a_cm, b_cm), abs(a_cm - b_cm)
    return longer > 0 and excess > min_difference * longer and excess > min_cm


def gathered_seams(pattern: Pattern, min_difference: float, min_cm: float) -> list[int]:
    """Indices of the pattern's seams that a wrap gathers (`gathers`, on the pattern's edge lengths)."""
    return [
        s
        for s, seam in enumerate(pattern.seams)
        if gathers(pattern.edge_length(seam.a), pattern.edge_length(seam.b), min_difference, min_cm)
    ]


def gathered_rest(
    pm: PatternMesh, welded: Welded, *, min_difference: float, min_cm: float, depth_cm: float
) -> tuple[np.ndarray, list[Gather]]:
    """The rest corners (F, 3, 2) metres of `welded`'s faces with every seam whose sides differ by more than
    `min_difference` (a fraction of the longer side) and by more than `min_cm` gathered, and the gathers made.

    A triangle of a gathered piece at distance d (cm, from its centroid to the nearest gathered seam side of that
    piece, in its pattern plane) is compressed about its centroid along that seam's direction there by
    s = r + (1 - r) * smoothstep(d / depth_cm), r that seam's length ratio. Only the nearest gathered seam counts:
    an edge split between several seams (a waistband sewn to fourteen skirt panels) is gathered once.
    """
    rest = welded.rest_corners.copy()
    if not depth_cm > 0:
        return rest, []
    uv = pm.vertices_cm
    sides: dict[int, list[tuple[int, np.ndarray, float]]] = {}  # piece -> (seam, its longer side, ratio)
    for s, pairs in enumerate(pm.seam_vertices):
        if len(pairs) < 2:
            continue
        lengths = [float(np.linalg.norm(np.diff(uv[pairs[:, k]], axis=0), axis=1).sum()) for k in (0, 1)]
        longer = int(np.argmax(lengths))
        if not gathers(lengths[0], lengths[1], min_difference, min_cm):
            continue
        piece = int(pm.vertex_piece[pairs[0, longer]])
        sides.setdefault(piece, []).append((s, uv[pairs[:, longer]], lengths[1 - longer] / lengths[longer]))
    face_piece = np.searchsorted(welded.piece_faces[:, 1], np.arange(len(rest)), side="right")
    centroid_cm = rest.mean(axis=1) * 100.0
    made: list[Gather] = []
    for piece, seams in sides.items():
        faces = np.flatnonzero(face_piece == piece)
        near = [_nearest_along(centroid_cm[faces], line) for _, line, _ in seams]
        which = np.argmin(np.stack([d for d, _ in near]), axis=0)
        d = np.choose(which, [d for d, _ in near])
        t = np.stack([t for _, t in near])[which, np.arange(len(faces))]
        ratio = np.array([r for _, _, r in seams])[which]
        keep = d < depth_cm
        faces, d, t, ratio, which = faces[keep], d[keep], t[keep], ratio[keep], which[keep]
        x = d / depth_cm
        scale = ratio + (1.0 - ratio) * x * x * (3.0 - 2.0 * x)
        c = rest[faces].mean(axis=1, keepdims=True)
        rel = rest[faces] - c
        along = np.einsum("fkc,fc->fk", rel, t)
        rest[faces] = c + rel - ((1.0 - scale)[:, None] * along)[..., None] * t[:, None, :]
        for k, (s, _, r) in enumerate(seams):
            made.append(Gather(s, pm.piece_names[piece], r, int((which == k).sum())))
    return rest, sorted(made, key=lambda g: g.seam)


def _nearest_along(points: np.ndarray, line: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Distance (n,) from each point (n, 2) to the polyline (k, 2), and the unit direction (n, 2) of the segment
    nearest it."""
    a, b = line[:-1], line[1:]
    ab = b - a
    ab2 = np.maximum((ab * ab).sum(axis=1), 1e-300)
    t = np.clip(np.einsum("nsc,sc->ns", points[:, None] - a[None], ab) / ab2, 0.0, 1.0)
    q = a[None] + t[..., None] * ab[None]
    d2 = ((q - points[:, None]) ** 2).sum(axis=2)
    best = np.argmin(d2, axis=1)
    direction = ab[best] / np.sqrt(ab2[best])[:, None]
    return np.sqrt(d2[np.arange(len(points)), best]), direction
