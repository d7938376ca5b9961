"""Plane geometry of pattern edges: curves in GarmentCode's relative coordinates, polylines, areas, intersections.

Relative control points (GarmentCode's convention, checked against pygarment's `rel_to_abs_2d`): for an edge from
`p0` to `p1` with `e = p1 - p0`, a relative point `(x, y)` is at `p0 + x * e + y * perp(e)` where
`perp(e) = (-e_y, e_x)` is `e` turned 90 degrees counter-clockwise. So `x` runs along the edge (0 at the start,
1 at the end) and `y` across it as a fraction of the edge's length, positive to the left of the edge's direction
-- that is, into the piece for a counter-clockwise outline.

Everything here is plain numpy on small arrays (an edge has a handful of control points; a densified outline a few
hundred points) and is called once per edge, not per vertex.
"""

from __future__ import annotations

import math
from math import comb

import numpy as np

#: Curve kinds and how many relative control points each carries.
CONTROL_COUNT = {"quadratic": 1, "cubic": 2, "circle": 1}

#: Default chord tolerance of sampled curves, cm: the polyline stays within this distance of the true curve.
SAMPLE_TOL_CM = 0.01
#: Tolerance for lengths and areas (finer: these are compared at 1% and 0.5%).
MEASURE_TOL_CM = 1e-3


def perp(v: np.ndarray) -> np.ndarray:
    """`v` turned 90 degrees counter-clockwise; (..., 2) -> (..., 2)."""
    return np.stack([-v[..., 1], v[..., 0]], axis=-1)


def rel_to_abs(p0: np.ndarray, p1: np.ndarray, rel: np.ndarray) -> np.ndarray:
    """Relative control points (k, 2) of the edge p0 -> p1 to absolute positions (k, 2), same units as p0."""
    e = p1 - p0
    rel = np.asarray(rel, dtype=np.float64).reshape(-1, 2)
    return p0 + rel[:, :1] * e + rel[:, 1:] * perp(e)


def abs_to_rel(p0: np.ndarray, p1: np.ndarray, pts: np.ndarray) -> np.ndarray:
    """Inverse of `rel_to_abs`: absolute points (k, 2) to relative coordinates of the edge p0 -> p1."""
    e = p1 - p0
    ee = float(e @ e)
    d = np.asarray(pts, dtype=np.float64).reshape(-1, 2) - p0
    return np.stack([d @ e / ee, d @ perp(e) / ee], axis=-1)


def _arc_geometry(p0: np.ndarray, p1: np.ndarray, y: float) -> tuple[np.ndarray, float, float, float]:
    """Circle arc from p0 to p1 through the relative point (0.5, y): centre, radius, start angle, signed sweep."""
    chord = float(np.linalg.norm(p1 - p0))
    if not chord > 0.0:  # a zero-length edge (which `validate` refuses): a point
        return np.array(p0, dtype=np.float64), 0.0, 0.0, 0.0
    h = abs(y) * chord  # sagitta: distance of the arc's middle from the chord
    radius = (h * h + 0.25 * chord * chord) / (2.0 * h)
    mid = rel_to_abs(p0, p1, np.array([[0.5, y]]))[0]
    toward_mid = perp(p1 - p0) / chord * math.copysign(1.0, y)
    centre = mid - radius * toward_mid
    sweep = 2.0 * math.atan2(0.5 * chord, radius - h)  # in (0, 2 pi): large arcs when h > radius
    start = math.atan2(p0[1] - centre[1], p0[0] - centre[0])
    # Through a middle point on the left of p0 -> p1 the arc turns clockwise (negative angles), and vice versa.
    return centre, radius, start, -math.copysign(sweep, y)


def _is_straight(kind: str | None, control: np.ndarray | None) -> bool:
    if kind is None or control is None:
        return True
    if kind == "circle":
        return abs(float(control[0, 1])) < 1e-9
    return False


def curve_point_count(p0: np.ndarray, p1: np.ndarray, kind: str | None, control: np.ndarray | None, tol: float) -> int:
    """Segments needed so that uniform sampling of the curve stays within `tol` of it (at least 1)."""
    if _is_straight(kind, control):
        return 1
    if kind == "circle":
        _, radius, _, sweep = _arc_geometry(p0, p1, float(control[0, 1]))
        if tol >= radius:
            return 4
        return max(4, math.ceil(abs(sweep) / (2.0 * math.acos(1.0 - tol / radius))))
    c = rel_to_abs(p0, p1, control)
    # Uniform flattening error <= max|B''| / (8 n^2) for a polynomial curve.
    if kind == "quadratic":
        m2 = 2.0 * float(np.linalg.norm(p0 - 2 * c[0] + p1))
    else:
        m2 = 6.0 * max(float(np.linalg.norm(p0 - 2 * c[0] + c[1])), float(np.linalg.norm(c[0] - 2 * c[1] + p1)))
    return max(2, math.ceil(math.sqrt(m2 / (8.0 * tol))))


def curve_points(
    p0: np.ndarray, p1: np.ndarray, kind: str | None, control: np.ndarray | None, t: np.ndarray
) -> np.ndarray:
    """Points (len(t), 2) of the edge p0 -> p1 at parameters t in [0, 1] (uniform in angle for arcs)."""
    t = np.asarray(t, dtype=np.float64)[:, None]
    if _is_straight(kind, control):
        return p0 + t * (p1 - p0)
    if kind == "circle":
        centre, radius, start, sweep = _arc_geometry(p0, p1, float(control[0, 1]))
        a = start + sweep * t[:, 0]
        return centre + radius * np.stack([np.cos(a), np.sin(a)], axis=-1)
    c = rel_to_abs(p0, p1, control)
    s = 1.0 - t
    if kind == "quadratic":
        return s * s * p0 + 2 * s * t * c[0] + t * t * p1
    return s**3 * p0 + 3 * s * s * t * c[0] + 3 * s * t * t * c[1] + t**3 * p1


def sample_curve(
    p0: np.ndarray, p1: np.ndarray, kind: str | None, control: np.ndarray | None, tol: float
) -> np.ndarray:
    """A polyline (m, 2) from p0 to p1 (both included) within `tol` of the curve."""
    n = curve_point_count(p0, p1, kind, control, tol)
    pts = curve_points(p0, p1, kind, control, np.linspace(0.0, 1.0, n + 1))
    pts[0], pts[-1] = p0, p1  # exact ends: neighbouring edges share them bit for bit
    return pts


def curve_length(p0: np.ndarray, p1: np.ndarray, kind: str | None, control: np.ndarray | None, tol: float) -> float:
    """Arc length of an edge: exact for lines and circle arcs, a polyline within `tol` for Béziers."""
    if _is_straight(kind, control):
        return float(np.linalg.norm(p1 - p0))
    if kind == "circle":
        _, radius, _, sweep = _arc_geometry(p0, p1, float(control[0, 1]))
        return radius * abs(sweep)
    return polyline_length(sample_curve(p0, p1, kind, control, tol))


def curve_length_bound(p0: np.ndarray, p1: np.ndarray, kind: str | None, control: np.ndarray | None) -> float:
    """An edge's arc length at bounded cost, whatever its numbers (for the size limits, before any sampling):
    exact for lines and arcs; for a Bézier its control polygon's length when that is short (an upper bound), else
    a 1,000-segment polyline's (within a fraction of a percent of it)."""
    if not float(np.linalg.norm(p1 - p0)) > 0.0:
        return 0.0  # a zero-length edge: `validate` names it
    if kind in (None, "circle") or control is None:
        return curve_length(p0, p1, kind, control, MEASURE_TOL_CM)
    hull = polyline_length(np.vstack([p0, rel_to_abs(p0, p1, control), p1]))
    if hull <= 1e3:
        return hull
    return polyline_length(curve_points(p0, p1, kind, control, np.linspace(0.0, 1.0, 1001)))


_GL_T, _GL_W = np.polynomial.legendre.leggauss(8)
_GL_T, _GL_W = 0.5 * (_GL_T + 1.0), 0.5 * _GL_W  # on [0, 1]


def edge_area_term(p0: np.ndarray, p1: np.ndarray, kind: str | None, control: np.ndarray | None) -> float:
    """The edge's share of a closed outline's signed area: (1/2) * integral of (x dy - y dx) along it. Exact for
    lines, arcs and Béziers (8-point Gauss-Legendre integrates their polynomial integrand exactly)."""
    if _is_straight(kind, control):
        return 0.5 * float(p0[0] * p1[1] - p0[1] * p1[0])
    if kind == "circle":
        centre, r, a0, sweep = _arc_geometry(p0, p1, float(control[0, 1]))
        a1 = a0 + sweep
        cx, cy = centre
        return 0.5 * (r * cx * (math.sin(a1) - math.sin(a0)) - r * cy * (math.cos(a1) - math.cos(a0)) + r * r * sweep)
    c = rel_to_abs(p0, p1, control)
    pts = np.vstack([p0, c, p1])  # Bézier control polygon
    deg = len(pts) - 1
    t = _GL_T[:, None]
    # Bernstein evaluation of the curve and its derivative at the nodes.
    basis = np.stack([comb(deg, i) * t[:, 0] ** i * (1 - t[:, 0]) ** (deg - i) for i in range(deg + 1)], axis=1)
    dbasis = np.stack([comb(deg - 1, i) * t[:, 0] ** i * (1 - t[:, 0]) ** (deg - 1 - i) for i in range(deg)], axis=1)
    xy = basis @ pts
    dxy = deg * (dbasis @ np.diff(pts, axis=0))
    return 0.5 * float(_GL_W @ (xy[:, 0] * dxy[:, 1] - xy[:, 1] * dxy[:, 0]))


def polyline_length(pts: np.ndarray) -> float:
    return float(np.linalg.norm(np.diff(pts, axis=0), axis=1).sum())


def resample_polyline(pts: np.ndarray, n_segments: int) -> np.ndarray:
    """(n_segments + 1, 2) points equally spaced by arc length along the polyline `pts`, ends kept exactly."""
    seg = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    s = np.concatenate([[0.0], np.cumsum(seg)])
    target = np.linspace(0.0, s[-1], n_segments + 1)
    out = np.stack([np.interp(target, s, pts[:, 0]), np.interp(target, s, pts[:, 1])], axis=-1)
    out[0], out[-1] = pts[0], pts[-1]
    return out


def signed_area(poly: np.ndarray) -> float:
    """Shoelace area of a closed polygon (n, 2) (last point not repeated); positive when counter-clockwise."""
    x, y = poly[:, 0], poly[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))


def self_intersections(poly: np.ndarray, *, eps: float = 1e-9) -> tuple[int, int] | None:
    """First pair of non-adjacent segments of the closed polygon `poly` (n, 2) that cross or touch, else None.

    Segment i runs from point i to point i+1 (wrapping). Vectorised one row block at a time (O(n^2) tests, fine
    for the few hundred points of a densified outline).
    """
    n = len(poly)
    a = poly
    b = np.roll(poly, -1, axis=0)
    scale = float(np.ptp(poly, axis=0).max()) or 1.0
    tol = eps * scale * scale

    def orient(p, q, r):  # twice the signed area of (p, q, r), broadcast
        return (q[..., 0] - p[..., 0]) * (r[..., 1] - p[..., 1]) - (q[..., 1] - p[..., 1]) * (r[..., 0] - p[..., 0])

    idx = np.arange(n)
    block = 256
    for s0 in range(0, n, block):
        i = idx[s0 : s0 + block, None]
        ai, bi = a[s0 : s0 + block, None, :], b[s0 : s0 + block, None, :]
        aj, bj = a[None, :, :], b[None, :, :]
        o1, o2 = orient(ai, bi, aj), orient(ai, bi, bj)
        o3, o4 = orient(aj, bj, ai), orient(aj, bj, bi)
        cross = (o1 * o2 < -tol * tol) & (o3 * o4 < -tol * tol)
        # A point of one segment lying on the other (touching), beyond the shared corner of neighbours.
        seg_len2 = np.maximum(((bj - aj) ** 2).sum(-1), 1e-300)
        near_line = tol * np.sqrt(seg_len2) / scale  # |orient| of a point within eps * scale of segment j
        t_a = ((ai - aj) * (bj - aj)).sum(-1) / seg_len2
        t_b = ((bi - aj) * (bj - aj)).sum(-1) / seg_len2
        touch = ((np.abs(o3) <= near_line) & (t_a > 1e-9) & (t_a < 1 - 1e-9)) | (
            (np.abs(o4) <= near_line) & (t_b > 1e-9) & (t_b < 1 - 1e-9)
        )
        same_point = ((ai - aj) ** 2).sum(-1) <= (eps * scale) ** 2
        hit = cross | touch | same_point
        j = idx[None, :]
        adjacent = (j == i) | (j == (i + 1) % n) | (j == (i - 1) % n)
        hit &= ~adjacent
        if hit.any():
            r, c = np.argwhere(hit)[0]
            return int(s0 + r), int(c)
    return None


def euler_xyz_matrix(rotation_deg: np.ndarray) -> np.ndarray:
    """Rotation matrix (3, 3) of XYZ Euler angles in degrees, applied X first: R = Rz @ Ry @ Rx.

    This is GarmentCode's (and Maya's default) rotate order, and scipy's extrinsic "xyz".
    """
    rx, ry, rz = np.radians(np.asarray(rotation_deg, dtype=np.float64))
    cx, sx, cy, sy, cz, sz = math.cos(rx), math.sin(rx), math.cos(ry), math.sin(ry), math.cos(rz), math.sin(rz)
    mx = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    my = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    mz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
    return mz @ my @ mx


def matrix_to_euler_xyz(m: np.ndarray) -> np.ndarray:
    """Inverse of `euler_xyz_matrix`: XYZ Euler angles in degrees, each in (-180, 180].

    Of the two equivalent triples the one with the smaller total turn is returned ([0, 180, 0] rather than
    [180, 0, 180]).
    """
    sy = -float(m[2, 0])
    if abs(sy) < 1 - 1e-12:
        ry = math.asin(sy)
        rx = math.atan2(m[2, 1], m[2, 2])
        rz = math.atan2(m[1, 0], m[0, 0])
        candidates = [(rx, ry, rz), (rx + math.pi, math.pi - ry, rz + math.pi)]
    else:  # gimbal lock: Y at +-90 degrees; put the whole remaining turn on X
        ry = math.copysign(math.pi / 2, sy)
        candidates = [(math.atan2(-m[1, 2], m[1, 1]), ry, 0.0)]
    best = None
    for c in candidates:
        deg = (np.degrees(c) + 180.0) % 360.0 - 180.0
        deg[np.isclose(deg, -180.0)] = 180.0
        deg[np.abs(deg) < 1e-12] = 0.0
        if best is None or np.abs(deg).sum() < np.abs(best).sum() - 1e-9:
            best = deg
    return best


def split_curve(
    p0: np.ndarray, p1: np.ndarray, kind: str | None, control: np.ndarray | None, t: float
) -> tuple[np.ndarray, np.ndarray | None, np.ndarray | None]:
    """Split the edge p0 -> p1 at parameter t in (0, 1): the point there (2,) and each half's relative control
    points (None for a straight half). Béziers split by de Casteljau; an arc into two arcs of the same circle."""
    mid = curve_points(p0, p1, kind, control, np.array([t]))[0]
    if _is_straight(kind, control):
        return mid, None, None
    if kind == "circle":
        _, radius, _, sweep = _arc_geometry(p0, p1, float(control[0, 1]))

        def half(part: float) -> np.ndarray:
            phi = abs(sweep) * part  # the half's own sweep: chord 2 r sin(phi/2), sagitta r (1 - cos(phi/2))
            y = (1.0 - math.cos(0.5 * phi)) / (2.0 * math.sin(0.5 * phi))
            return np.array([[0.5, math.copysign(y, float(control[0, 1]))]])

        return mid, half(t), half(1.0 - t)
    c = rel_to_abs(p0, p1, control)
    if kind == "quadratic":
        a, b = p0 + t * (c[0] - p0), c[0] + t * (p1 - c[0])
        return mid, abs_to_rel(p0, mid, a), abs_to_rel(mid, p1, b)
    ab, bc, cd = p0 + t * (c[0] - p0), c[0] + t * (c[1] - c[0]), c[1] + t * (p1 - c[1])
    abc, bcd = ab + t * (bc - ab), bc + t * (cd - bc)
    return mid, abs_to_rel(p0, mid, np.stack([ab, abc])), abs_to_rel(mid, p1, np.stack([bcd, cd]))
