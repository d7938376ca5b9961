"""Sewing a meshed pattern into one garment mesh: seam vertices shared, vertices in a cache-friendly order."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..cloth import locality_order
from ..pattern import PatternMesh


@dataclass
class Welded:
    """A pattern mesh with its seams sewn (one vertex per group of seam vertices), in locality order.

    vertex_of : (Vp,) int64, the garment vertex of each pattern-mesh vertex.
    faces : (F, 3) int64, garment vertex indices; face i is pattern face face_order[i].
    face_order : (F,) int64, the pattern face of each garment face (pieces stay contiguous: see piece_faces).
    rest_corners : (F, 3, 2) float64, metres, each corner's pattern position in its piece.
    corner_vertex : (F, 3) int64, the pattern-mesh vertex of each corner (its `vt`).
    piece_faces : (P, 2) int64, [start, stop) garment face range of each piece.
    n_vertices : V, garment vertices.
    """

    vertex_of: np.ndarray
    faces: np.ndarray
    face_order: np.ndarray
    rest_corners: np.ndarray
    corner_vertex: np.ndarray
    piece_faces: np.ndarray
    n_vertices: int


def weld(pm: PatternMesh) -> Welded:
    """Share the vertices of every seam of `pm` (transitively: a corner where three seams meet becomes one vertex)
    and order vertices by reverse Cuthill-McKee; faces keep the pattern's piece order (pieces contiguous), sorted
    by locality inside each piece."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    nv = pm.n_vertices
    pairs = np.concatenate(
        [np.asarray(s, dtype=np.int64).reshape(-1, 2) for s in pm.seam_vertices] or [np.zeros((0, 2), np.int64)]
    )
    g = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(nv, nv))
    _, label = connected_components(g, directed=False)
    # Compact the labels in order of first appearance so that unsewn vertices keep the pattern's order.
    _, first, inverse = np.unique(label, return_index=True, return_inverse=True)
    rank = np.argsort(np.argsort(first))
    merged = rank[inverse].astype(np.int64)
    n = int(merged.max()) + 1
    faces = merged[pm.faces]
    vorder, _ = locality_order(faces, n)
    new_of_old = np.empty(n, dtype=np.int64)
    new_of_old[vorder] = np.arange(n)
    vertex_of = new_of_old[merged]
    faces = vertex_of[pm.faces]
    # Faces: piece by piece, inside each piece by their lowest vertex (locality), so piece ranges stay valid.
    piece_of_face = np.repeat(np.arange(len(pm.piece_faces)), np.diff(pm.piece_faces, axis=1).reshape(-1))
    face_order = np.lexsort((faces.min(axis=1), piece_of_face)).astype(np.int64)
    return Welded(
        vertex_of=vertex_of,
        faces=np.ascontiguousarray(faces[face_order]),
        face_order=face_order,
        rest_corners=np.ascontiguousarray(pm.vertices_cm[pm.faces[face_order]] / 100.0),
        corner_vertex=np.ascontiguousarray(pm.faces[face_order]),
        piece_faces=np.asarray(pm.piece_faces, dtype=np.int64).copy(),
        n_vertices=n,
    )
