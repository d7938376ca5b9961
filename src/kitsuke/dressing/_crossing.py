"""Which triangles of a meshed pattern piece a 2D stroke crosses (the triangles the wrap transfers first).

A segment and a triangle in the plane are disjoint exactly when some line parallel to an edge of either
separates them (separating axes of two convex polygons; a segment is a degenerate one whose only edge
direction is its own). So per (segment, triangle) pair four projections decide it: onto the segment's normal
and onto the three edge normals of the triangle. A distance test of triangle centroids first cuts the pairs down to
those near each segment (a ball around its midpoint); the exact test is vectorised over the candidate pairs.
"""

from __future__ import annotations

import numpy as np

#: (segment, triangle) pairs whose centroid distance is computed at once (bounds the temporary arrays).
BLOCK_PAIRS = 2_000_000


def _perp(v: np.ndarray) -> np.ndarray:
    return np.stack([-v[..., 1], v[..., 0]], axis=-1)


def _overlap(axis: np.ndarray, seg: np.ndarray, tri: np.ndarray, tol: float) -> np.ndarray:
    """(k,) bool: the projections of segments (k, 2, 2) and triangles (k, 3, 2) onto axes (k, 2) overlap."""
    ps = np.einsum("kij,kj->ki", seg, axis)
    pt = np.einsum("kij,kj->ki", tri, axis)
    slack = tol * np.linalg.norm(axis, axis=1)
    return np.maximum(ps.min(1), pt.min(1)) <= np.minimum(ps.max(1), pt.max(1)) + slack


def segments_cross_triangles(
    points: np.ndarray, triangles: np.ndarray, *, tol: float | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """All (segment, triangle) pairs that intersect or touch, for a 2D polyline and a triangle soup.

    points : (m, 2) float64 polyline; segment i runs from point i to point i + 1.
    triangles : (F, 3, 2) float64.
    tol : how close counts as touching, in the inputs' units (default 1e-9 of the extent).
    Returns (segment (k,), triangle (k,)) int64 index arrays, sorted by segment then triangle.
    """
    p = np.asarray(points, dtype=np.float64).reshape(-1, 2)
    tri = np.asarray(triangles, dtype=np.float64).reshape(-1, 3, 2)
    if len(p) < 2 or len(tri) == 0:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    seg = np.stack([p[:-1], p[1:]], axis=1)  # (m-1, 2, 2)
    if tol is None:
        extent = float(np.ptp(np.vstack([p, tri.reshape(-1, 2)]), axis=0).max())
        tol = 1e-9 * max(extent, 1e-300)
    # Candidates: triangles whose centroid lies within (half the segment + the triangle's reach) of the
    # segment's midpoint, found in blocks of segments against every centroid (numpy alone: importing
    # scipy.spatial for a k-d tree took 0.3 s of every wrap), instead of testing every pair exactly.
    centroid = tri.mean(axis=1)
    reach = float(np.linalg.norm(tri - centroid[:, None], axis=2).max())
    mid = seg.mean(axis=1)
    radius = 0.5 * np.linalg.norm(seg[:, 1] - seg[:, 0], axis=1) + reach + tol
    block = max(1, BLOCK_PAIRS // len(tri))
    out_s, out_t = [], []
    for b0 in range(0, len(seg), block):
        gap = mid[b0 : b0 + block, None, :] - centroid[None, :, :]
        near = (gap * gap).sum(axis=2) <= radius[b0 : b0 + block, None] ** 2
        si, ti = np.nonzero(near)
        if not len(si):
            continue
        si = si + b0
        s, t = seg[si], tri[ti]
        ok = _overlap(_perp(s[:, 1] - s[:, 0]), s, t, tol)
        for k in range(3):
            ok &= _overlap(_perp(t[:, (k + 1) % 3] - t[:, k]), s, t, tol)
        out_s.append(si[ok])
        out_t.append(ti[ok])
    if not out_s:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    si, ti = np.concatenate(out_s).astype(np.int64), np.concatenate(out_t).astype(np.int64)
    order = np.lexsort((ti, si))
    return si[order], ti[order]
