"""Polylines: arc length, resampling (in the plane, in space and on a surface), stroke coordinates, polygons.

Plain vectorised numpy on strokes of a few to a few hundred points; nothing here loops per point in Python.
"""

from __future__ import annotations

import numpy as np

from ..geometry.polygon import polygon_inside
from ..geometry.surface import Surface, SurfacePoints


def arc_length(points: np.ndarray) -> np.ndarray:
    """Cumulative arc length (n,) float64 of a polyline (n, d), in the points' units; 0 at the first point."""
    p = np.asarray(points, dtype=np.float64)
    if len(p) == 0:
        return np.zeros(0)
    seg = np.linalg.norm(np.diff(p, axis=0), axis=1)
    return np.concatenate([[0.0], np.cumsum(seg)])


def arc_parameters(points: np.ndarray) -> np.ndarray:
    """Normalised arc-length parameter (n,) in [0, 1] of each point of a polyline (n, d); ValueError if its
    length is zero."""
    s = arc_length(points)
    if len(s) < 2 or s[-1] <= 0:
        raise ValueError("a polyline of zero length has no arc-length parameter")
    return s / s[-1]


def interpolate_polyline(points: np.ndarray, s: np.ndarray) -> np.ndarray:
    """Points (m, d) at arc lengths s (m,) along a polyline (n, d) (clamped to its ends)."""
    p = np.asarray(points, dtype=np.float64)
    cum = arc_length(p)
    s = np.clip(np.asarray(s, dtype=np.float64).reshape(-1), 0.0, cum[-1])
    # Segment of each sample: the last knot at or before it, ignoring zero-length segments.
    seg = np.clip(np.searchsorted(cum, s, side="right") - 1, 0, len(p) - 2)
    length = cum[seg + 1] - cum[seg]
    t = np.divide(s - cum[seg], length, out=np.zeros_like(s), where=length > 0)
    return p[seg] + t[:, None] * (p[seg + 1] - p[seg])


def resample_polyline(points: np.ndarray, k: int) -> np.ndarray:
    """`k` >= 2 points (k, d) equally spaced by arc length along a polyline (n, d), both ends kept exactly."""
    p = np.asarray(points, dtype=np.float64)
    if k < 2:
        raise ValueError("resample_polyline needs k >= 2")
    if len(p) < 2:
        raise ValueError("resample_polyline needs a polyline of at least 2 points")
    cum = arc_length(p)
    out = interpolate_polyline(p, np.linspace(0.0, cum[-1], k))
    out[0], out[-1] = p[0], p[-1]
    return out


def densify_polyline(points: np.ndarray, step: float) -> np.ndarray:
    """The polyline (n, d) with each segment split into pieces no longer than `step`; original points kept."""
    p = np.asarray(points, dtype=np.float64)
    if len(p) < 2:
        return p.copy()
    seg = np.diff(p, axis=0)
    counts = np.maximum(1, np.ceil(np.linalg.norm(seg, axis=1) / step).astype(np.int64))
    seg_of = np.repeat(np.arange(len(seg)), counts)
    frac = (np.arange(counts.sum()) - np.repeat(np.cumsum(counts) - counts, counts)) / counts[seg_of]
    return np.vstack([p[seg_of] + frac[:, None] * seg[seg_of], p[-1:]])


def surface_polyline(surface: Surface, points: np.ndarray, *, step_m: float = 0.005) -> SurfacePoints:
    """A polyline (n, 3) metres drawn near a surface, densified to `step_m` and projected onto the surface
    point by point: the path it traces on the surface (its chords no longer cut through curved parts)."""
    return surface.closest(densify_polyline(points, step_m))


def surface_length(surface: Surface, points: np.ndarray, *, step_m: float = 0.005) -> float:
    """Length in metres of the path a polyline (n, 3) traces on a surface (see `surface_polyline`)."""
    return float(arc_length(surface_polyline(surface, points, step_m=step_m).points)[-1])


def resample_on_surface(surface: Surface, points: np.ndarray, k: int, *, step_m: float = 0.005) -> SurfacePoints:
    """`k` surface points equally spaced by arc length along the path that a polyline (n, 3) metres traces on
    the surface (densified to `step_m`, projected, measured, resampled, projected again); ends are the
    projections of the polyline's ends."""
    path = surface_polyline(surface, points, step_m=step_m).points
    return surface.closest(resample_polyline(path, k))


def stroke_coordinates(points: np.ndarray, stroke: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Coordinates of 2D points relative to a 2D stroke polyline: where along it and how far across.

    points : (n, 2) query points. stroke : (m, 2) polyline, m >= 2.
    Returns (s, offset, segment): s (n,) arc length of each point's closest point on the stroke; offset (n,)
    its signed distance from the stroke, positive to the left of the stroke's direction; segment (n,) int64
    the closest segment. Beyond the ends, s is clamped to [0, length] and offset is the distance to the end
    point (signed by the end segment's side). Units are the inputs'. Memory O(n m).
    """
    q = np.asarray(points, dtype=np.float64).reshape(-1, 2)
    p = np.asarray(stroke, dtype=np.float64).reshape(-1, 2)
    if len(p) < 2:
        raise ValueError("stroke_coordinates needs a stroke of at least 2 points")
    a, e = p[:-1], np.diff(p, axis=0)
    ee = np.einsum("ij,ij->i", e, e)
    rel = q[:, None, :] - a[None, :, :]  # (n, m-1, 2)
    t = np.clip(np.divide(np.einsum("nmk,mk->nm", rel, e), ee, out=np.zeros(rel.shape[:2]), where=ee > 0), 0, 1)
    diff = rel - t[..., None] * e[None]
    d2 = np.einsum("nmk,nmk->nm", diff, diff)
    seg = np.argmin(d2, axis=1)
    rows = np.arange(len(q))
    cum = arc_length(p)
    s = cum[seg] + t[rows, seg] * np.sqrt(ee[seg])
    cross = e[seg, 0] * rel[rows, seg, 1] - e[seg, 1] * rel[rows, seg, 0]
    side = np.where(cross >= 0, 1.0, -1.0)
    return s, side * np.sqrt(d2[rows, seg]), seg.astype(np.int64)


def polygon_grid(polygon: np.ndarray, n: int) -> np.ndarray:
    """(m, 2): the points of an n x n grid over a polygon's (k, 2) bounding box that lie inside it."""
    lo, hi = polygon.min(axis=0), polygon.max(axis=0)
    gx, gy = np.meshgrid(np.linspace(lo[0], hi[0], n), np.linspace(lo[1], hi[1], n))
    grid = np.c_[gx.ravel(), gy.ravel()]
    return grid[polygon_inside(grid, polygon)]


def polygon_distance(points: np.ndarray, polygon: np.ndarray) -> np.ndarray:
    """(n,) distance of points (n, 2) to the boundary of a closed polygon (m, 2), in the points' units."""
    q = np.asarray(points, dtype=np.float64).reshape(-1, 2)
    a = np.asarray(polygon, dtype=np.float64)
    e = np.roll(a, -1, axis=0) - a
    ee = np.einsum("ij,ij->i", e, e)
    rel = q[:, None, :] - a[None]
    t = np.clip(np.divide(np.einsum("nmk,mk->nm", rel, e), ee, out=np.zeros(rel.shape[:2]), where=ee > 0), 0, 1)
    diff = rel - t[..., None] * e[None]
    return np.sqrt(np.einsum("nmk,nmk->nm", diff, diff).min(axis=1))
