"""Pieces that a layout put far from the body, drawn in to it for `suggest_strokes`.

GarmentCode lays a wide skirt's panels out in a ring 1-2 m from the body (so that they do not cross before its
simulation sews them), at about the height they hang, their outer faces turned out from the body. Carried along
their normals, no point of them reaches the body. Their seams still say where they go: a skirt panel is sewn to
a waistband or a bodice that GarmentCode laid on the body. `drawn_in` moves such a piece rigidly (no rotation):

1. up or down so that its seams meet the pieces already on the body (`seam_rise`: the median height difference
   along the seams; through other far pieces, drawn in first, for a panel sewn only to its neighbours);
2. then horizontally towards the body's vertical axis until the nearest point of its upper half reaches the
   body's outline as seen from that axis (`outline_radius`: the first place a ray from the axis outwards leaves
   the body, so that a hand hanging beside the hips does not stop a skirt panel short of them; the feet in front
   of a long skirt's hem do not either).

The moved piece is then carried to the body along its normal as any other. A pattern none of whose pieces lies
near the body gets nothing here: its placement was made for another body.
"""

from __future__ import annotations

import numpy as np

from ..geometry.surface import Surface
from ..pattern import Pattern, Piece, Placement
from ._polyline import polygon_grid

#: Points per seam compared when a piece's height is matched to the pieces it is sewn to.
SEAM_SAMPLES = 8
#: Grid cells across a piece's bounding box for the points that find where it first meets the body's outline.
CONTACT_GRID = 24


def body_axis(surface: Surface) -> np.ndarray:
    """(2,) metres: x and z of the body's vertical axis (the median of its vertices: arms and hands that stick
    out to one side, or a dense head mesh, do not move it much)."""
    return np.median(surface.vertices[:, [0, 2]], axis=0)


def outline_radius(surface: Surface, axis: np.ndarray, points: np.ndarray) -> np.ndarray:
    """(n,) metres: for each point (n, 3), how far from the vertical axis `axis` (2,) the body ends at the
    point's height in the point's horizontal direction from the axis: where a ray from the axis outwards first
    leaves the body (through the torso's side, not into a hand beyond it; from between the legs, through the
    leg it meets). NaN where the ray leaves no body (above the head, below the feet, past the legs)."""
    out = np.full(len(points), np.nan)
    d = np.zeros_like(points)
    d[:, [0, 2]] = points[:, [0, 2]] - axis
    r = np.linalg.norm(d, axis=1)
    ok = r > 1e-6
    if not ok.any():
        return out
    idx = np.flatnonzero(ok)
    d = d[idx] / r[idx, None]
    origins = np.c_[np.full(len(idx), axis[0]), points[idx, 1], np.full(len(idx), axis[1])]
    ray, hits = surface.ray_hits(origins, d)
    if not len(ray):
        return out
    leaving = np.einsum("ij,ij->i", surface.normals_at(hits.faces), d[ray]) > 0
    ray, dist = ray[leaving], hits.distance[leaving]
    first = np.r_[True, ray[1:] != ray[:-1]]  # hits come sorted by ray, then distance
    out[idx[ray[first]]] = dist[first]
    return out


def seam_rise(pattern: Pattern, name: str, anchors: dict[str, Placement]) -> float | None:
    """Metres to raise piece `name` so that its seams with the pieces in `anchors` (their placements) meet in
    height: the median over points along those seams; None when it is sewn to none of them."""
    own = pattern.piece(name).placement
    rise = []
    for seam in pattern.seams:
        for mine, other in ((seam.a, seam.b), (seam.b, seam.a)):
            if mine.piece != name or other.piece == name or other.piece not in anchors:
                continue
            pa, pb = pattern.seam_points(seam, SEAM_SAMPLES)
            here, there = (pa, pb) if mine is seam.a else (pb, pa)
            rise.append(anchors[other.piece].apply(there)[:, 1] - own.apply(here)[:, 1])
    return float(np.median(np.concatenate(rise))) if rise else None


def near_body(piece: Piece, surface: Surface, reach_m: float) -> bool:
    """Whether the placed piece's outline comes within `reach_m` metres of the body."""
    placed = piece.placement.apply(piece.polygon())
    return bool(surface.closest(placed).distance.min() <= reach_m)


def drawn_in(piece: Piece, rise: float, surface: Surface, axis: np.ndarray) -> tuple[Placement, float] | None:
    """The piece's placement moved `rise` metres up and then horizontally towards `axis` (2,) metres until the
    nearest of its points reaches the body's outline (module docstring), and the height (metres) of that point;
    None when none of its points is at a height and in a direction where the body has an outline."""
    pl = piece.placement
    lifted = Placement(pl.translation + [0.0, rise, 0.0], pl.rotation_deg.copy(), pl.fold)
    world = lifted.apply(polygon_grid(piece.polygon(), CONTACT_GRID))
    away = world[:, [0, 2]].mean(axis=0) - axis
    if np.linalg.norm(away) < 1e-6:
        return None
    away /= np.linalg.norm(away)
    radial = world[:, [0, 2]] - axis
    r = np.linalg.norm(radial, axis=1)
    gap = r - outline_radius(surface, axis, world)
    # Moving along -away by s brings a point about s * cos(angle to away) nearer the axis; points off to the
    # side (a wide piece's edges) count as at most twice as far as they are.
    cos = np.einsum("ij,j->i", radial, away) / np.maximum(r, 1e-9)
    # Only the upper half of the piece may stop it: it hangs from there (a skirt panel from the hips), and the
    # lower half hangs free over what sticks out below (the feet in front of a long skirt).
    upper = world[:, 1] >= 0.5 * (world[:, 1].min() + world[:, 1].max())
    ok = np.flatnonzero(np.isfinite(gap) & (cos > 0) & upper)
    if not len(ok):
        return None
    need = gap[ok] / np.maximum(cos[ok], 0.5)
    k = int(np.argmin(need))
    s = max(0.0, float(need[k]))
    moved = Placement(lifted.translation - s * np.array([away[0], 0.0, away[1]]), lifted.rotation_deg, pl.fold)
    return moved, float(world[ok[k], 1])


def drawn_in_placements(
    pattern: Pattern, names: list[str], surface: Surface, reach_m: float
) -> dict[str, tuple[Placement, float]]:
    """`drawn_in` (placement, height where it meets the body) for those of the pieces `names` (placed) that lie
    farther than `reach_m` metres from the body, by name: each raised to meet its seams with the pieces near the
    body or with far ones drawn in before it, then moved in. A piece sewn to none of them, directly or through
    others, is left out."""
    near = {pc.name for pc in pattern.pieces if pc.placement is not None and near_body(pc, surface, reach_m)}
    anchors = {name: pattern.piece(name).placement for name in near}
    if not anchors:
        return {}
    axis = body_axis(surface)
    todo, out = [name for name in names if name not in near], {}
    while todo:
        rises = {name: seam_rise(pattern, name, anchors) for name in todo}
        ready = [name for name in todo if rises[name] is not None]
        if not ready:
            break
        for name in ready:
            todo.remove(name)
            piece = pattern.piece(name)
            moved = drawn_in(piece, rises[name], surface, axis)
            if moved is not None:
                out[name] = moved
                anchors[name] = moved[0]
    return out
