"""The quality measures of SPEC §6 as pure functions over arrays."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..geometry import TriMesh
from ..geometry.validate import edge_topology


def _points(a, what: str, n: int | None = None) -> np.ndarray:
    arr = np.asarray(a, dtype=np.float64)
    if arr.ndim != 2 or arr.shape[1] != 3 or (n is not None and len(arr) != n):
        want = f"({n}, 3)" if n is not None else "(n, 3)"
        raise InputError(f"{what} must have shape {want}, got {arr.shape}")
    if not np.isfinite(arr).all():
        raise InputError(f"{what} hold NaN or infinity")
    return np.ascontiguousarray(arr)


def _faces(f, n_vertices: int, what: str = "faces") -> np.ndarray:
    arr = np.asarray(f)
    if arr.ndim != 2 or arr.shape[1] != 3 or not np.issubdtype(arr.dtype, np.integer):
        raise InputError(f"{what} must be integer indices of shape (F, 3), got {arr.shape} {arr.dtype}")
    if len(arr) and (arr.min() < 0 or arr.max() >= n_vertices):
        raise InputError(f"{what} refer to vertices outside 0..{n_vertices - 1}")
    return np.ascontiguousarray(arr, dtype=np.int64)


def mesh_edges(faces: np.ndarray) -> np.ndarray:
    """(E, 2) int64 unique undirected edges of faces (F, 3), sorted pairs in lexicographic order — the order
    `kitsuke.cloth.ClothModel.edges` and `rest_lengths` use."""
    f = np.asarray(faces, dtype=np.int64)
    return edge_topology(f)[0] if len(f) else np.zeros((0, 2), dtype=np.int64)


@dataclass
class Penetration:
    """Cloth vertices inside the body.

    count : vertices deeper inside than the threshold. deepest_mm : depth of the deepest vertex inside, mm (0 if
    none). depth_m : (n,) float64, metres, depth of each vertex inside the body (0 outside). threshold_mm : the
    threshold used.
    """

    count: int
    deepest_mm: float
    depth_m: np.ndarray
    threshold_mm: float


def penetration(points: np.ndarray, body: TriMesh, *, threshold_m: float = 0.002) -> Penetration:
    """Penetration of cloth vertices `points` (n, 3) metres into a closed `body` mesh.

    Inside is decided by the generalised winding number (libigl's fast winding number > 0.5), which stays right
    far from the surface and for slightly open meshes, where a nearest-normal test can be fooled; the depth of an
    inside vertex is its distance to the nearest body point (libigl AABB). A vertex counts when its signed
    distance is below -threshold_m.
    """
    import igl

    pts = _points(points, "points")
    if not isinstance(body, TriMesh):
        raise InputError("body must be a TriMesh")
    if not threshold_m >= 0:
        raise InputError(f"threshold_m must be >= 0, got {threshold_m}")
    depth = np.zeros(len(pts))
    if len(pts):
        w = igl.fast_winding_number(body.vertices, body.faces, pts)
        inside = np.flatnonzero(w > 0.5)
        if len(inside):
            d2, _, _ = igl.point_mesh_squared_distance(pts[inside], body.vertices, body.faces)
            depth[inside] = np.sqrt(d2)
    return Penetration(
        count=int((depth > threshold_m).sum()),
        deepest_mm=float(depth.max(initial=0.0) * 1e3),
        depth_m=depth,
        threshold_mm=threshold_m * 1e3,
    )


@dataclass
class Strain:
    """Edge strain |current length / rest length - 1|.

    per_edge : (E,) float64 (dimensionless). mean, max : over all edges. worst_edges : (k,) int64 edge indices,
    largest strain first. stretched, compressed : the largest stretch and compression (both >= 0).
    """

    per_edge: np.ndarray
    mean: float
    max: float
    worst_edges: np.ndarray
    stretched: float
    compressed: float


def strain(positions: np.ndarray, edges: np.ndarray, rest_lengths: np.ndarray, *, worst: int = 10) -> Strain:
    """Strain of every edge (E, 2) of cloth at `positions` (V, 3) metres against rest_lengths (E,) metres (from
    the pattern)."""
    pos = _points(positions, "positions")
    e = np.asarray(edges)
    if e.ndim != 2 or e.shape[1] != 2 or not np.issubdtype(e.dtype, np.integer):
        raise InputError(f"edges must be integer pairs of shape (E, 2), got {e.shape}")
    if len(e) and (e.min() < 0 or e.max() >= len(pos)):
        raise InputError("edges refer to vertices that do not exist")
    rest = np.asarray(rest_lengths, dtype=np.float64)
    if rest.shape != (len(e),):
        raise InputError(f"rest_lengths must have shape ({len(e)},), got {rest.shape}")
    if not (np.isfinite(rest).all() and (rest > 0).all()):
        raise InputError("rest_lengths must be finite and positive")
    ratio = np.linalg.norm(pos[e[:, 0]] - pos[e[:, 1]], axis=1) / rest - 1.0
    s = np.abs(ratio)
    order = np.argsort(-s, kind="stable")[:worst]
    return Strain(
        per_edge=s,
        mean=float(s.mean()) if len(s) else 0.0,
        max=float(s.max(initial=0.0)),
        worst_edges=order.astype(np.int64),
        stretched=float(max(ratio.max(initial=0.0), 0.0)),
        compressed=float(max(-ratio.min(initial=0.0), 0.0)),
    )


@dataclass
class SeamGap:
    """Distance between the two sides of seams. max_mm : over all seams (0 for none). per_seam_mm : max per seam."""

    max_mm: float
    per_seam_mm: list[float]


def seam_gap(positions: np.ndarray, seams: Sequence[tuple[np.ndarray, np.ndarray]]) -> SeamGap:
    """Largest distance between matching vertices of the two sides of each seam, in mm.

    seams : per seam, two index arrays (k,) of equal length: vertex i of side a meets vertex i of side b. Sides
    that share vertices (a sewn mesh) have gap 0.
    """
    pos = _points(positions, "positions")
    per = []
    for n, pair in enumerate(seams):
        try:
            a, b = (np.asarray(x) for x in pair)
        except (TypeError, ValueError):
            raise InputError(f"seam {n} must be a pair of index arrays") from None
        if a.shape != b.shape or a.ndim != 1 or not (np.issubdtype(a.dtype, np.integer) or a.size == 0):
            raise InputError(f"seam {n}: the two sides must be integer index arrays of equal length")
        if a.size and (min(a.min(), b.min()) < 0 or max(a.max(), b.max()) >= len(pos)):
            raise InputError(f"seam {n} refers to vertices that do not exist")
        a, b = a.astype(np.int64), b.astype(np.int64)
        per.append(float(np.linalg.norm(pos[a] - pos[b], axis=1).max(initial=0.0) * 1e3))
    return SeamGap(max(per, default=0.0), per)


#: A triangle whose 3D area is below this fraction of its rest area has collapsed (no usable orientation).
COLLAPSE_RATIO = 0.01


def inverted_triangles(positions: np.ndarray, faces: np.ndarray, *, rest_areas: np.ndarray | None = None) -> np.ndarray:
    """(F,) bool: triangles that are inverted (folded over) after placement.

    Definition. The 2D pattern fixes each triangle's orientation: its corners in face order run counter-clockwise
    seen from the piece's outer face (a flipped piece is wound the other way), so the 3D normal by the winding
    points out of the garment's outer face, and within a rest piece all triangles agree. A map from the flat rest
    triangle onto its 3D triangle alone is never "reflected" (any triangle in space can be reached by a rotation),
    so inversion is judged against the neighbours, which share the same rest orientation. A triangle is inverted
    when

    (a) the sum of the unit normals of its edge neighbours (each turned to agree with this triangle's winding
    across the shared edge) points against its own unit normal — it is folded back over them (on average a
    dihedral angle below 90°), the 3D surface has reversed its rest orientation there; or
    (b) `rest_areas` (F,) is given and its 3D area is below COLLAPSE_RATIO (1 %) of its rest area — it has
    collapsed and has no orientation.

    A triangle without neighbours is judged by (b) only. A whole piece turned inside out is not inverted by this
    measure (nothing nearby disagrees); whether the outer face looks away from the body is for the wrap to check.
    """
    pos = _points(positions, "positions")
    f = _faces(faces, len(pos))
    tri = pos[f]
    cr = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    area2 = np.linalg.norm(cr, axis=1)
    n = np.divide(cr, area2[:, None], out=np.zeros_like(cr), where=area2[:, None] > 0)
    # Neighbours across each undirected edge, and whether they are wound like this face.
    nv = len(pos)
    a, b = f.reshape(-1), f[:, [1, 2, 0]].reshape(-1)
    key = np.minimum(a, b) * nv + np.maximum(a, b)
    order = np.argsort(key, kind="stable")
    ks = key[order]
    pair = np.flatnonzero(ks[1:] == ks[:-1])
    h1, h2 = order[pair], order[pair + 1]
    same_dir = a[h1] == a[h2]  # both faces run the edge the same way: wound oppositely
    sign = np.where(same_dir, -1.0, 1.0)[:, None]
    m = np.zeros_like(n)
    np.add.at(m, h1 // 3, sign * n[h2 // 3])
    np.add.at(m, h2 // 3, sign * n[h1 // 3])
    folded = np.einsum("ij,ij->i", n, m) < 0
    collapsed = np.zeros(len(f), dtype=bool)
    if rest_areas is not None:
        ra = np.asarray(rest_areas, dtype=np.float64)
        if ra.shape != (len(f),):
            raise InputError(f"rest_areas must have shape ({len(f)},), got {ra.shape}")
        collapsed = 0.5 * area2 < COLLAPSE_RATIO * ra
    return folded | collapsed


def vertex_strain(positions: np.ndarray, faces: np.ndarray, rest_edge_lengths: np.ndarray) -> np.ndarray:
    """(V,) float64: the largest strain (|length / rest - 1|) of the triangle edges at each vertex, for strain
    maps. positions (V, 3) metres; faces (F, 3); rest_edge_lengths (F, 3) metres, edges 0-1, 1-2, 2-0."""
    pos = _points(positions, "positions")
    f = _faces(faces, len(pos))
    rest = np.asarray(rest_edge_lengths, dtype=np.float64)
    if rest.shape != f.shape:
        raise InputError(f"rest_edge_lengths must have shape {f.shape}, got {rest.shape}")
    length = np.linalg.norm(pos[f[:, [1, 2, 0]]] - pos[f], axis=2)
    s = np.abs(length / np.maximum(rest, 1e-12) - 1.0)  # (F, 3): edge k runs from corner k to k + 1
    out = np.zeros(len(pos))
    for k in range(3):
        np.maximum.at(out, f[:, k], s[:, k])
        np.maximum.at(out, f[:, (k + 1) % 3], s[:, k])
    return out
