"""Where a triangle mesh crosses a horizontal plane: the crossing faces and points, and the separate pieces of the
cross-section (a torso and two arms at the chest, two legs at the knees)."""

from __future__ import annotations

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components


def plane_cut(vertices: np.ndarray, faces: np.ndarray, y: float):
    """The faces crossing the plane Y = y, and for each its two crossing edges: (faces (k,), edges (k, 2, 2) vertex
    pairs, corner pairs (k, 2, 2) (0-2 within the face), t (k, 2) the crossing's share along each edge)."""
    s = vertices[faces, 1] - y  # (F, 3)
    s = np.where(s == 0.0, 1e-12, s)  # a vertex on the plane counts as above it
    side = s > 0
    crossing = side.any(axis=1) & ~side.all(axis=1)
    idx = np.flatnonzero(crossing)
    differ = side[idx] != np.roll(side[idx], -1, axis=1)  # (k, 3): edge c (corner c to c + 1) crosses; two do
    first, last = np.argmax(differ, axis=1), 2 - np.argmax(differ[:, ::-1], axis=1)
    corners = np.stack([np.c_[first, (first + 1) % 3], np.c_[last, (last + 1) % 3]], axis=1)  # (k, 2, 2)
    a, b = corners[..., 0], corners[..., 1]
    sa, sb = np.take_along_axis(s[idx], a, axis=1), np.take_along_axis(s[idx], b, axis=1)
    t = sa / (sa - sb)
    fv = faces[idx]
    edges = np.stack([np.take_along_axis(fv, a, axis=1), np.take_along_axis(fv, b, axis=1)], axis=2)
    return idx, edges, corners, t


def cut_points(vertices: np.ndarray, edges: np.ndarray, t: np.ndarray) -> np.ndarray:
    """(k, 2, 3) the crossing points on each face's two crossing edges."""
    return vertices[edges[..., 0]] * (1.0 - t[..., None]) + vertices[edges[..., 1]] * t[..., None]


def section_parts(vertices: np.ndarray, faces: np.ndarray, y: float) -> list[np.ndarray]:
    """The cross-section of the mesh (`vertices` (V, 3) metres, `faces` (F, 3)) with the plane Y = y, split into
    its connected parts: one (m, 3) array of crossing points per part (two points per crossing face, shared with
    the neighbouring faces), largest part first. Faces are joined where they cross the plane through the same
    edge, so parts are separate wherever the surface is, however far apart its vertices lie."""
    idx, edges, _, t = plane_cut(vertices, faces, y)
    if not len(idx):
        return []
    key = np.sort(edges.reshape(-1, 2), axis=1)  # (2k, 2): each crossing edge, as the two faces that share it see it
    _, node = np.unique(key, axis=0, return_inverse=True)
    node = node.reshape(-1, 2)
    n = int(node.max()) + 1
    graph = coo_matrix((np.ones(len(node)), (node[:, 0], node[:, 1])), shape=(n, n))
    count, label = connected_components(graph, directed=False)
    points = cut_points(vertices, edges, t).reshape(-1, 3)
    part = label[node.reshape(-1)]
    parts = [points[part == c] for c in range(count)]
    return sorted(parts, key=len, reverse=True)
