"""How far round a garment goes at one height, at rest and worn, against the body it goes round.

    from kitsuke.metrics import garment_girth
    g = garment_girth(positions, faces, rest_corners, body_mesh, point)   # Girth or None
    g.short       # 0.15: the cloth's own length round the body is 15 % less than the body's girth there

A garment cut smaller than the body (GarmentCode's fitted designs have no ease, and a low waistband sits on the
hips) must stretch to go round it, however it is dressed. Where its worst strain lies, the horizontal loop of
cloth through that point tells a user whether the pattern or the dressing is to blame: the loop's rest length
(the pattern's own lengths, summed along the cut) against the body's girth inside it, measured as a tape measure
would (the perimeter of the convex hull of the body's cross-sections the loop goes round: a loop round both
thighs spans the gap between them).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..geometry import TriMesh
from ..geometry.polygon import convex_hull, polygon_inside
from ..geometry.section import cut_points, plane_cut

#: A cut of the cloth open by at most this much (metres: a dart's open end, a seam whose two sides were meshed
#: apart) still counts as a loop; the gap adds nothing to the cloth's length round it.
GAP_M = 0.03
#: Where the cut at the worst edge's height finds no loop (the edge runs along a hem), it is tried this far
#: below and above, metres.
NUDGE_M = 0.005
#: A loop's path is thinned to at most this many points when the body inside it is found (a loop of 1.5 cm
#: cloth round the hips crosses 200 triangles; 64 of its points follow it within millimetres).
RING_POINTS = 64


@dataclass(frozen=True)
class Girth:
    """A closed horizontal loop of cloth round the body.

    height_m : the loop's height (Y), metres. rest_m : the cloth's rest length round it (its pattern's lengths),
    metres. worn_m : its length round it as worn. body_m : the tape girth of the body inside it, metres.
    """

    height_m: float
    rest_m: float
    worn_m: float
    body_m: float

    @property
    def short(self) -> float:
        """The share by which the cloth round the loop is shorter than the body's girth (negative: longer)."""
        return 1.0 - self.rest_m / self.body_m

    def to_dict(self) -> dict:
        return {
            "height_m": round(self.height_m, 4),
            "rest_cm": round(100 * self.rest_m, 1),
            "worn_cm": round(100 * self.worn_m, 1),
            "body_cm": round(100 * self.body_m, 1),
            "short": round(self.short, 4),
        }


def _loop(edges: np.ndarray, points: np.ndarray, start: int, gap_m: float) -> list[int] | None:
    """The crossing faces (indices into `edges` (k, 2, 2), crossing points `points` (k, 2, 3)) in order round the
    closed loop through face `start`, or None where it does not close. Where the cut leaves the cloth (a slit, a
    dart's open end, a seam whose sides were meshed apart) it goes on from the nearest other such place within
    `gap_m` metres."""
    key = np.sort(edges, axis=2)
    at: dict[tuple[int, int], list[int]] = {}
    for j in range(len(key)):
        for e in range(2):
            at.setdefault((int(key[j, e, 0]), int(key[j, e, 1])), []).append(j)
    sides = [(j, e) for j in range(len(key)) for e in range(2)]
    open_sides = [(j, e) for j, e in sides if len(at[(int(key[j, e, 0]), int(key[j, e, 1]))]) == 1]
    order, seen, j, came = [start], {start}, start, 1
    for _ in range(len(key)):
        out = tuple(int(v) for v in key[j, 1 - came])
        nxt = [m for m in at[out] if m != j]
        if nxt:
            j = nxt[0]
            came = 0 if tuple(int(v) for v in key[j, 0]) == out else 1
        else:  # off the cloth: on from the nearest place the cut comes back onto it
            here = points[j, 1 - came]
            near = [(float(np.linalg.norm(points[m, e] - here)), m, e) for m, e in open_sides if m != j]
            near = [c for c in near if c[0] <= gap_m and (c[1] not in seen or c[1] == start)]
            if not near:
                return None
            _, j, came = min(near)
        if j == start:
            return order
        if j in seen:
            return None
        order.append(j)
        seen.add(j)
    return None


def _hull_perimeter(points: np.ndarray) -> float:
    """The perimeter of the convex hull of points (n, 2); 0 where they span no area (all on a line)."""
    hull = convex_hull(points)
    if hull is None:
        return 0.0
    ring = points[hull.vertices]
    return float(np.linalg.norm(ring - np.roll(ring, 1, axis=0), axis=1).sum())


def garment_girth(
    positions: np.ndarray, faces: np.ndarray, rest_corners: np.ndarray, body: TriMesh, point: np.ndarray
) -> Girth | None:
    """The horizontal loop of cloth through the face nearest `point` (3,) (metres): its rest and worn lengths and
    the body's tape girth inside it. positions (V, 3) metres, faces (F, 3), rest_corners (F, 3, 2) metres (each
    corner's rest position, `ClothModel.rest_corners`). None when the cut there does not close round the body
    (an open piece, a loop that goes round no part of the body)."""
    for dy in (0.0, -NUDGE_M, NUDGE_M):  # an edge along a hem is cut again just inside the cloth
        got = _girth(np.asarray(positions, dtype=np.float64), np.asarray(faces), rest_corners, body, point, dy)
        if got is not None:
            return got
    return None


@dataclass(frozen=True)
class WornLoop:
    """A closed horizontal loop of worn cloth: height_m (Y, metres), rest_m (the cloth's rest length round it,
    metres), worn_m (its worn length), ring (n, 2) float64: the loop's worn path seen from above (x, z metres)."""

    height_m: float
    rest_m: float
    worn_m: float
    ring: np.ndarray


def worn_loop(
    positions: np.ndarray, faces: np.ndarray, rest_corners: np.ndarray, y: float, point: np.ndarray | None = None
) -> WornLoop | None:
    """The loop of cloth cut by the plane Y = y through the crossing face nearest `point` (3,) metres (None: the
    front-most crossing, the body facing +Z); None where the cut there does not close. positions (V, 3) metres,
    faces (F, 3), rest_corners (F, 3, 2) metres."""
    pos = np.asarray(positions, dtype=np.float64)
    idx, edges, corners, t = plane_cut(pos, np.asarray(faces), y)
    if len(idx) == 0:
        return None
    worn = cut_points(pos, edges, t)  # (k, 2, 3)
    middle = worn.mean(axis=1)
    start = int(np.argmax(middle[:, 2]) if point is None else np.argmin(np.linalg.norm(middle - point, axis=1)))
    order = _loop(edges, worn, start, GAP_M)
    if order is None:
        return None
    o = np.asarray(order)
    rc = np.asarray(rest_corners)[idx]  # (k, 3, 2)
    rest = (
        rc[np.arange(len(idx))[:, None], corners[..., 0]] * (1.0 - t[..., None])
        + rc[np.arange(len(idx))[:, None], corners[..., 1]] * t[..., None]
    )
    rest_m = float(np.linalg.norm(rest[o, 0] - rest[o, 1], axis=1).sum())
    worn_m = float(np.linalg.norm(worn[o, 0] - worn[o, 1], axis=1).sum())
    return WornLoop(float(y), rest_m, worn_m, worn[o, 0][:, [0, 2]])


def body_section(body: TriMesh, y: float) -> np.ndarray:
    """(n, 2) x, z metres: where the body's surface crosses the plane Y = y (two points per crossing face)."""
    idx, edges, _, t = plane_cut(body.vertices, body.faces, y)
    return cut_points(body.vertices, edges, t).reshape(-1, 3)[:, [0, 2]] if len(idx) else np.zeros((0, 2))


def tape_inside(section: np.ndarray, ring: np.ndarray, *, margin_m: float = 0.0) -> float:
    """A tape measure's girth (metres) round the body's cross-section points `section` (n, 2) (`body_section`)
    inside `ring` (m, 2) x, z metres, widened about its centre by `margin_m` (a loop moved to another height,
    where the body leans a little further out); 0 where none lies inside."""
    if len(section) == 0 or len(ring) < 3:
        return 0.0
    if margin_m:
        centre = ring.mean(axis=0)
        radius = float(np.linalg.norm(ring - centre, axis=1).mean())
        ring = centre + (ring - centre) * (1.0 + margin_m / max(radius, 1e-9))
    box = ((section >= ring.min(axis=0)) & (section <= ring.max(axis=0))).all(axis=1)  # the cheap test first
    candidates = section[box]
    ring = ring[np.linspace(0, len(ring), min(len(ring), RING_POINTS), endpoint=False).astype(np.int64)]
    return _hull_perimeter(candidates[polygon_inside(candidates, ring)])


def _girth(
    pos: np.ndarray, faces: np.ndarray, rest_corners: np.ndarray, body: TriMesh, point: np.ndarray, dy: float
) -> Girth | None:
    point = np.asarray(point, dtype=np.float64) + [0.0, dy, 0.0]
    loop = worn_loop(pos, faces, rest_corners, float(point[1]), point)
    if loop is None:
        return None
    tape = tape_inside(body_section(body, loop.height_m), loop.ring)
    return Girth(loop.height_m, loop.rest_m, loop.worn_m, tape) if tape > 0.0 else None
