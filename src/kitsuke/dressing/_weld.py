"""Sewing a meshed pattern into one garment mesh: seam vertices shared, vertices in a cache-friendly order.

Where two seams of one piece end at the same corner (a kimono sleeve: its bottom and its outer side are both sewn
to the piece itself), the corner triangles of the two sides get the same three garment vertices once sewn, and
their inner edges are shared by four triangles. `repair_corners` splits such an inner pattern edge at its
midpoint (a new pattern vertex, inside its piece), which makes the sewn garment a manifold: the bag's corner
closes to a flat cone instead of two coincident triangles.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from ..cloth import locality_order
from ..errors import InputError
from ..geometry.validate import edge_topology
from ..pattern import PatternMesh

#: Rounds of `repair_corners` before giving up (one round fixes every corner seen on the shipped patterns).
REPAIR_ROUNDS = 4


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


def _sewn(pm: PatternMesh) -> np.ndarray:
    """(V,) int64: the garment vertex of every pattern vertex once every seam is sewn (transitively: a corner
    where three seams meet becomes one vertex), numbered in order of first appearance."""
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
    return rank[inverse].astype(np.int64)


def _bad_edges(pm: PatternMesh, merged: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Interior pattern edges (k, 2) to split, and the count of non-manifold garment edges no split repairs.

    Every garment edge used by more than two faces is made of one or more pattern edges; the first of them stays,
    every other one that is an interior pattern edge (two faces) is split."""
    n = pm.n_vertices
    f = pm.faces
    pe = np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1)
    pkey, pcount = np.unique(pe[:, 0] * n + pe[:, 1], return_counts=True)  # unique pattern edges, faces on each
    upe = np.stack([pkey // n, pkey % n], axis=1)
    ge = np.sort(merged[upe], axis=1)
    _, ginv = np.unique(ge[:, 0] * n + ge[:, 1], return_inverse=True)
    ginv = ginv.reshape(-1)
    on_g = np.bincount(ginv, weights=pcount)  # faces on each garment edge
    hot = np.flatnonzero(on_g[ginv] > 2)
    hot = hot[np.argsort(ginv[hot], kind="stable")]
    first = np.r_[True, ginv[hot][1:] != ginv[hot][:-1]] if len(hot) else np.zeros(0, dtype=bool)
    split = hot[~first & (pcount[hot] == 2)]
    left = on_g - np.bincount(ginv[split], weights=pcount[split], minlength=len(on_g))
    return upe[split], int((left > 2).sum())


def _split_edges(pm: PatternMesh, split: np.ndarray) -> PatternMesh:
    """`pm` with interior pattern edges of `split` (k, 2, sorted pairs) cut at their midpoints, each of their two
    faces becoming two (a face with two such edges splits only its first; the next round takes the other). New
    vertices go at the end of their piece's vertex range; every index is renumbered."""
    n = pm.n_vertices
    f = pm.faces
    fkey = np.sort(np.stack([f, np.roll(f, -1, axis=1)], axis=2), axis=2)  # (F, 3, 2): edge j = (f[j], f[j+1])
    fkey = fkey[..., 0] * n + fkey[..., 1]
    skey = split[:, 0] * n + split[:, 1]
    hit = np.isin(fkey, skey)
    cut = np.flatnonzero(hit.any(axis=1))
    j = np.argmax(hit[cut], axis=1)
    used = np.unique(fkey[cut, j])  # the edges actually cut this round
    split = np.stack([used // n, used % n], axis=1)
    piece = pm.vertex_piece[split[:, 0]].astype(np.int64)
    order = np.argsort(piece, kind="stable")
    split, piece, used = split[order], piece[order], used[order]
    added = np.bincount(piece, minlength=len(pm.piece_names))
    before = np.r_[0, np.cumsum(added)[:-1]]
    old_new = np.arange(n) + before[pm.vertex_piece]
    pv = pm.piece_vertices + np.c_[before, before + added]
    new_ids = pv[piece, 1] - added[piece] + (np.arange(len(split)) - before[piece])
    nvert = n + len(split)
    vcm, pos = np.empty((nvert, 2)), np.empty((nvert, 3))
    vpiece = np.empty(nvert, dtype=pm.vertex_piece.dtype)
    vcm[old_new], pos[old_new], vpiece[old_new] = pm.vertices_cm, pm.positions_m, pm.vertex_piece
    vcm[new_ids] = pm.vertices_cm[split].mean(axis=1)
    pos[new_ids] = pm.positions_m[split].mean(axis=1)
    vpiece[new_ids] = piece
    # Face (a, b, c) cut on edge (a, b) at m becomes (a, m, c) and (m, b, c): same orientation, same piece.
    a, b, c = f[cut, j], f[cut, (j + 1) % 3], f[cut, (j + 2) % 3]
    sorter = np.argsort(used)
    m = new_ids[sorter[np.searchsorted(used, fkey[cut, j], sorter=sorter)]]
    faces = old_new[f]
    faces[cut] = np.stack([old_new[a], m, old_new[c]], axis=1)
    extra = np.stack([m, old_new[b], old_new[c]], axis=1)
    # Insert each second half right after its face so every piece's faces stay contiguous.
    faces = np.insert(faces, cut + 1, extra, axis=0)
    grown = np.bincount(np.searchsorted(pm.piece_faces[:, 1], cut, side="right"), minlength=len(pm.piece_names))
    ends = pm.piece_faces[:, 1] + np.cumsum(grown)
    pf = np.stack([np.r_[0, ends[:-1]], ends], axis=1)
    return dataclasses.replace(
        pm,
        vertices_cm=vcm,
        positions_m=pos,
        faces=faces.astype(np.int64),
        vertex_piece=vpiece,
        piece_vertices=pv.astype(np.int64),
        piece_faces=pf.astype(np.int64),
        edge_vertices={e: old_new[v] for e, v in pm.edge_vertices.items()},
        seam_vertices=[old_new[np.asarray(s, dtype=np.int64)] for s in pm.seam_vertices],
    )


def _where(pm: PatternMesh, merged: np.ndarray, seams: list | None) -> str:
    """Where sewing leaves a garment edge on more than two triangles: the seams whose vertices it joins (named
    from `seams`, the pattern's Seam list, when given) and a pattern point of it."""
    edges, count = edge_topology(merged[pm.faces])
    hot = edges[count > 2]
    if not len(hot):
        return ""
    at = np.flatnonzero(np.isin(merged, hot[0]))
    involved = [i for i, sv in enumerate(pm.seam_vertices) if np.isin(np.asarray(sv).reshape(-1), at).any()]
    piece = pm.piece_names[int(pm.vertex_piece[at[0]])]
    x, y = pm.vertices_cm[at[0]]
    if seams is not None:
        names = [
            f"seam {i} ({seams[i].a.piece} edge {seams[i].a.edge} - {seams[i].b.piece} edge {seams[i].b.edge})"
            for i in involved
        ]
    else:
        names = [f"seam {i}" for i in involved]
    return f" at ({x:.1f}, {y:.1f}) cm on piece {piece}" + (f", where {', '.join(names)} meet" if names else "")


def repair_corners(pm: PatternMesh, seams: list | None = None) -> PatternMesh:
    """`pm` itself if sewing its seams gives a manifold garment, else a copy with the inner edges of coinciding
    corner triangles split (see the module docstring). Raises InputError where more than two pattern edges are
    sewn together (three pieces on one seam), which no split repairs, naming the place and the seams (from
    `seams`, the pattern's Seam list, when given)."""
    for _ in range(REPAIR_ROUNDS):
        merged = _sewn(pm)
        split, hopeless = _bad_edges(pm, merged)
        if hopeless:
            raise InputError(
                f"pattern {pm.name!r}: {hopeless} seam edge(s) join more than two pieces' edges"
                f"{_where(pm, merged, seams)}; a seam joins exactly two edges"
            )
        if not len(split):
            return pm
        pm = _split_edges(pm, split)
    raise InputError(
        f"pattern {pm.name!r}: sewing its seams leaves edges shared by more than two triangles"
        f"{_where(pm, _sewn(pm), seams)}"
    )


def weld(pm: PatternMesh) -> Welded:
    """Share the vertices of every seam of `pm` and order vertices by reverse Cuthill-McKee; faces keep the
    pattern's piece order (pieces contiguous), sorted by locality inside each piece. `pm` must sew into a manifold
    (see `repair_corners`); raises InputError otherwise."""
    merged = _sewn(pm)
    n = int(merged.max()) + 1
    _, counts = edge_topology(merged[pm.faces])
    if (counts > 2).any():
        raise InputError(
            f"pattern {pm.name!r}: {int((counts > 2).sum())} sewn edges are shared by more than two triangles "
            "(repair_corners first)"
        )
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


def check_sewable(pattern, *, edge_length_cm: float = 1.5) -> PatternMesh:
    """Mesh `pattern` (a kitsuke Pattern) and sew it as the wrap would; the repaired PatternMesh, or InputError
    naming the seam and the place that cannot be sewn (what `kitsuke pattern validate` reports for `dress`)."""
    from ..pattern import mesh_pattern

    pm = repair_corners(mesh_pattern(pattern, edge_length=edge_length_cm), pattern.seams)
    weld(pm)
    return pm
