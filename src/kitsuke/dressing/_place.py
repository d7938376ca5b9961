"""Wrap step 1: the pattern triangles each pattern stroke crosses are laid onto the body along its body stroke.

A stroke says *where* the cloth lies, not how long it is: the pattern stroke keeps its own length and is laid
along the body stroke with their middles together (a pattern point s cm along its stroke goes s / 100 m along
the body stroke from where the pattern stroke starts, the body stroke continued straight past its ends where the
pattern stroke is longer). Stretching the pattern stroke to the body stroke's length, as the paper's arc-length
correspondence does, strains the placed cloth by the ratio of the two, which a hand does not keep at 1 (a body
stroke 10 % short: 31 % max strain after the wrap; 30 %: 179 %).

Its signed distance across the stroke is laid out along the body surface perpendicular to the stroke (the
direction normal x tangent, which is "left" of the stroke seen from outside, matching the pattern's left seen
from the piece's outer face), then projected back onto the surface and lifted `lift_m` off it along the normal.

Strokes may be drawn either way: where the pattern's placement (or, without one, the pattern's up, +y) says the
pattern stroke runs against its body stroke, the body stroke is taken the other way round (`stroke_reversed`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..cloth import BodyCollider
from ..errors import InputError
from ..geometry.surface import Surface
from ..pattern import PatternMesh
from ..pattern import Placement as PiecePlacement
from ._polyline import (
    arc_length,
    interpolate_polyline,
    resample_on_surface,
    resample_polyline,
    stroke_coordinates,
)
from ._weld import Welded
from .strokes import Strokes, triangles_crossed

#: Body stroke paths are followed on the surface at this spacing, metres.
PATH_STEP_M = 0.003
#: Pattern strokes are sampled at this many points for the residual (distance to the body stroke after wrap).
RESIDUAL_SAMPLES = 32


@dataclass
class StrokeTrack:
    """Where a pattern stroke lies on the garment and which body path it must follow.

    id : stroke id. faces : (n,) int64 garment faces holding the stroke's samples; bary : (n, 3) their
    barycentric coordinates. body_path : (k, 3) float64 metres, the body stroke traced on the surface, in the
    direction it was taken (see `reversed`), continued along the surface past its ends where the pattern stroke
    is longer (what the cloth stroke is held to and measured against).
    pattern_length_m, body_length_m : the two strokes' lengths, metres (the body stroke as drawn).
    reversed : the body stroke was taken against its drawing order (`stroke_reversed`).
    """

    id: int
    faces: np.ndarray
    bary: np.ndarray
    body_path: np.ndarray
    pattern_length_m: float
    body_length_m: float
    reversed: bool = False

    def points(self, positions: np.ndarray, faces: np.ndarray) -> np.ndarray:
        """(n, 3) the stroke's samples on the garment at `positions` (V, 3)."""
        return np.einsum("ij,ijk->ik", self.bary, positions[faces[self.faces]])

    def residual_m(self, positions: np.ndarray, faces: np.ndarray) -> float:
        """Largest distance, metres, from a sample of the pattern stroke on the garment to the body stroke."""
        return float(polyline_distance(self.points(positions, faces), self.body_path).max())


@dataclass
class Placement:
    """The transferred stroke triangles.

    positions : (V, 3) float64 metres (meaningful where `placed`). placed : (V,) bool. seed_faces : (F,) bool,
    garment faces crossed by a stroke. tracks : one StrokeTrack per stroke pair, in drawing order.
    """

    positions: np.ndarray
    placed: np.ndarray
    seed_faces: np.ndarray
    tracks: list[StrokeTrack]


def polyline_distance(points: np.ndarray, line: np.ndarray) -> np.ndarray:
    """(n,) distance of points (n, 3) to a polyline (k, 3), any units."""
    a, e = line[:-1], np.diff(line, axis=0)
    ee = np.maximum(np.einsum("ij,ij->i", e, e), 1e-300)
    rel = points[:, None, :] - a[None]
    t = np.clip(np.einsum("nmk,mk->nm", rel, e) / ee, 0.0, 1.0)
    d = rel - t[..., None] * e[None]
    return np.sqrt(np.einsum("nmk,nmk->nm", d, d).min(axis=1))


def smooth_normals(collider: BodyCollider, faces: np.ndarray, bary: np.ndarray) -> np.ndarray:
    """(n, 3) unit body normals interpolated from the vertex normals at surface points (faces, barycentrics)."""
    n = np.einsum("ij,ijk->ik", bary, collider.vertex_normals[collider.faces[faces]])
    return n / np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-300)


def _extended_coordinates(points_cm: np.ndarray, stroke_cm: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Like `stroke_coordinates` (s along, signed offset across, cm), but with the stroke continued straight past
    its ends: a point before the start gets s < 0 and its offset from the first segment's line, a point after the
    end s > length. (Clamping s there, as `stroke_coordinates` does, folds those points onto the end's normal
    line: measured on the shirt, edges of the transferred triangles strained up to 88 %.)"""
    s, off, _ = stroke_coordinates(points_cm, stroke_cm)
    length = float(arc_length(stroke_cm)[-1])
    for end, origin, d in (
        (0, stroke_cm[0], stroke_cm[1] - stroke_cm[0]),
        (1, stroke_cm[-1], stroke_cm[-1] - stroke_cm[-2]),
    ):
        d = d / max(float(np.hypot(*d)), 1e-300)
        rel = points_cm - origin
        along = rel @ d
        out = along < 0 if end == 0 else along > 0
        s = np.where(out, (0.0 if end == 0 else length) + along, s)
        off = np.where(out, d[0] * rel[:, 1] - d[1] * rel[:, 0], off)
    return s, off


def _locate(pm: PatternMesh, faces: np.ndarray, points_cm: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The face among `faces` holding each 2D point (the best one if on none) and its barycentric coordinates."""
    return locate_in_triangles(pm.vertices_cm[pm.faces[faces]], faces, points_cm)


def locate_in_triangles(tri: np.ndarray, faces: np.ndarray, points_cm: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The face among `faces` (m,) with 2D triangles `tri` (m, 3, 2) holding each point (n, 2) (the best one if on
    none) and its barycentric coordinates (n, 3)."""
    a, b, c = tri[:, 0], tri[:, 1], tri[:, 2]
    v0, v1 = b - a, c - a
    den = v0[:, 0] * v1[:, 1] - v0[:, 1] * v1[:, 0]
    rel = points_cm[:, None, :] - a[None]
    l1 = (rel[..., 0] * v1[None, :, 1] - rel[..., 1] * v1[None, :, 0]) / den[None]
    l2 = (v0[None, :, 0] * rel[..., 1] - v0[None, :, 1] * rel[..., 0]) / den[None]
    bary = np.stack([1 - l1 - l2, l1, l2], axis=-1)  # (n, m, 3)
    best = np.argmax(bary.min(axis=-1), axis=1)
    rows = np.arange(len(points_cm))
    bc = np.clip(bary[rows, best], 0.0, None)
    return faces[best], bc / bc.sum(axis=1, keepdims=True)


#: A pattern stroke runs against its body stroke when the cosine of their directions is below minus this.
AGAINST_COS = 0.3


def stroke_reversed(pattern_points: np.ndarray, body_path: np.ndarray, placement: PiecePlacement | None) -> bool:
    """Whether a body stroke (k, 3) metres was drawn the other way from its pattern stroke (n, 2) cm.

    With the piece's placement the pattern stroke's direction is carried into the world and compared with the
    body stroke's (end minus start); without one, the pattern's up (+y) is compared with the world's (+Y), and
    only strokes that run clearly up or down (cosine over 0.5 with the vertical on both sides) are judged."""
    dp = pattern_points[-1] - pattern_points[0]
    db = body_path[-1] - body_path[0]
    nb = float(np.linalg.norm(db))
    if nb < 1e-9 or float(np.hypot(*dp)) < 1e-9:
        return False
    if placement is not None:
        ends = placement.apply(pattern_points[[0, -1]])
        d3 = ends[1] - ends[0]
        n3 = float(np.linalg.norm(d3))
        return n3 > 1e-9 and float(d3 @ db) / (n3 * nb) < -AGAINST_COS
    up_p = dp[1] / float(np.hypot(*dp))
    up_b = db[1] / nb
    return abs(up_p) > 0.5 and abs(up_b) > 0.5 and up_p * up_b < 0


def extend_path(surface: Surface, path: np.ndarray, before_m: float, after_m: float) -> np.ndarray:
    """A surface path (k, 3) continued straight along its end directions by `before_m` and `after_m` metres and
    put back on the surface (every PATH_STEP_M)."""
    if before_m <= 0 and after_m <= 0:
        return path
    parts = [path]
    for amount, end, prev, at_start in ((before_m, 0, 1, True), (after_m, -1, -2, False)):
        if amount <= 0:
            continue
        d = path[end] - path[prev]
        d /= max(float(np.linalg.norm(d)), 1e-300)
        steps = np.arange(1, int(np.ceil(amount / PATH_STEP_M)) + 1) * (amount / np.ceil(amount / PATH_STEP_M))
        ext = surface.closest(path[end] + steps[:, None] * d).points
        parts = [ext[::-1], *parts] if at_start else [*parts, ext]
    return np.vstack(parts)


def place_strokes(
    pm: PatternMesh,
    welded: Welded,
    strokes: Strokes,
    surface: Surface,
    collider: BodyCollider,
    *,
    lift_m: float,
    placements: dict[str, PiecePlacement] | None = None,
) -> Placement:
    """Lay the triangles crossed by each pattern stroke onto the body along its (resolved) body stroke.

    placements : the pattern's piece placements by piece name (to tell which way a stroke runs), if any."""
    nv = welded.n_vertices
    acc = np.zeros((nv, 3))
    cnt = np.zeros(nv)
    seed = np.zeros(len(pm.faces), dtype=bool)
    garment_face_of = np.empty(len(pm.faces), dtype=np.int64)
    garment_face_of[welded.face_order] = np.arange(len(pm.faces))
    tracks = []
    path = strokes.source or None
    for pair in strokes.pairs:
        ps = pair.pattern
        crossed = triangles_crossed(pm, ps)
        if not len(crossed):
            raise InputError(f"stroke {pair.id}: pattern stroke crosses no triangle of piece {ps.piece!r}", path)
        k = pm.piece_names.index(ps.piece)
        # Orientation of the piece in its cm coordinates: faces are counter-clockwise seen from the outer face.
        f0, f1 = pm.piece_faces[k]
        t0 = pm.vertices_cm[pm.faces[f0]]
        d1, d2 = t0[1] - t0[0], t0[2] - t0[0]
        side = 1.0 if d1[0] * d2[1] - d1[1] * d2[0] > 0 else -1.0

        bpath, lb = body_path(surface, pair, path)
        flip = stroke_reversed(ps.points, bpath, (placements or {}).get(ps.piece))
        if flip:
            bpath = np.ascontiguousarray(bpath[::-1])
        lp = ps.length_cm

        vids = np.unique(pm.faces[crossed])
        x = lay_along(pm.vertices_cm[vids], ps, side, bpath, surface, collider, lift_m=lift_m)
        g = welded.vertex_of[vids]
        np.add.at(acc, g, x)
        np.add.at(cnt, g, 1.0)
        seed[crossed] = True

        samples = resample_polyline(ps.points, RESIDUAL_SAMPLES)
        pf, bary = _locate(pm, crossed, samples)
        over = max(0.0, 0.5 * (lp / 100.0 - lb))
        held = extend_path(surface, bpath, over, over)
        tracks.append(StrokeTrack(pair.id, garment_face_of[pf], bary, held, lp / 100.0, lb, flip))
    placed = cnt > 0
    pos = np.zeros((nv, 3))
    pos[placed] = acc[placed] / cnt[placed, None]
    return Placement(pos, placed, seed[welded.face_order], tracks)


def body_path(surface: Surface, pair, path: str | None) -> tuple[np.ndarray, float]:
    """The body stroke of `pair` traced on `surface` ((k, 3) metres, every PATH_STEP_M) and its length."""
    body_pts = pair.body.surface_points
    rough = arc_length(body_pts)[-1]
    n_path = int(np.clip(np.ceil(rough / PATH_STEP_M) + 1, 2, 2000))
    bpath = resample_on_surface(surface, body_pts, n_path).points
    lb = float(arc_length(bpath)[-1])
    if lb < 1e-3:
        raise InputError(f"stroke {pair.id}: body stroke has zero length on the surface", path)
    return bpath, lb


def lay_along(
    points_cm: np.ndarray,
    ps,
    side: float,
    bpath: np.ndarray,
    surface: Surface,
    collider: BodyCollider,
    *,
    lift_m: float,
    fit_length: bool = False,
) -> np.ndarray:
    """Positions (n, 3) metres on the body of pattern points (n, 2) cm near the pattern stroke `ps`: arc length
    along the stroke laid along the body path `bpath` (k, 3) at its own length, the middles together (module
    docstring), the offset across it laid out on the surface (`side` = the piece's orientation sign), `lift_m`
    off the surface. fit_length : stretch the pattern stroke to the whole body path instead (the paper's
    arc-length correspondence; the re-wrap's, whose strokes are drawn on the garment itself)."""
    lb = float(arc_length(bpath)[-1])
    lp = ps.length_cm
    s, off = _extended_coordinates(points_cm, np.asarray(ps.points, dtype=np.float64))
    if fit_length:
        along = s / lp * lb
    else:
        along = s / 100.0 + 0.5 * (lb - lp / 100.0)  # metres along the body path
    inside = np.clip(along, 0.0, lb)
    q = interpolate_polyline(bpath, inside)
    eps = min(0.01, 0.25 * lb)
    tangent = interpolate_polyline(bpath, inside + eps) - interpolate_polyline(bpath, inside - eps)
    on = surface.closest(q)
    normal = smooth_normals(collider, on.faces, on.barycentric)
    tangent -= np.einsum("ij,ij->i", tangent, normal)[:, None] * normal
    tangent /= np.maximum(np.linalg.norm(tangent, axis=1, keepdims=True), 1e-300)
    across = side * np.cross(normal, tangent)
    # Beyond its ends the body stroke is continued straight along its end tangent, so the crossed triangles that
    # stick out past an end keep their shape.
    beyond = along - inside
    x = on.points + beyond[:, None] * tangent + (off / 100.0)[:, None] * across
    proj = surface.closest(x)
    nx = smooth_normals(collider, proj.faces, proj.barycentric)
    return proj.points + lift_m * nx
