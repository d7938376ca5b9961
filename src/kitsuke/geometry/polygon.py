"""Plane polygons and point sets: inside tests and convex hulls (shared by stroke checks, girths and the kimono's
constraint calibration)."""

from __future__ import annotations

import numpy as np


def polygon_inside(points: np.ndarray, polygon: np.ndarray) -> np.ndarray:
    """(n,) bool: points (n, 2) inside a closed polygon (m, 2), last point not repeated (even-odd rule)."""
    q = np.asarray(points, dtype=np.float64).reshape(-1, 2)
    a = np.asarray(polygon, dtype=np.float64)
    b = np.roll(a, -1, axis=0)
    x, y = q[:, 0:1], q[:, 1:2]
    straddle = (a[None, :, 1] > y) != (b[None, :, 1] > y)
    dy = b[:, 1] - a[:, 1]
    with np.errstate(divide="ignore", invalid="ignore"):
        xc = a[None, :, 0] + (y - a[None, :, 1]) * (b[:, 0] - a[:, 0])[None, :] / dy[None, :]
    return ((straddle & (x < xc)).sum(axis=1) % 2) == 1


def convex_hull(points: np.ndarray):  # noqa: ANN201 - scipy ConvexHull, or None
    """The convex hull (scipy's ConvexHull) of points (n, 2), or None when they span no area."""
    from scipy.spatial import ConvexHull, QhullError

    if len(points) < 3:
        return None
    try:
        return ConvexHull(points)
    except QhullError:
        return None
