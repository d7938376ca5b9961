"""Mesh validation and cleaning: finite, non-empty, no degenerate or unreferenced elements; holes and
non-manifold edges reported (not repaired: a body with holes is still usable, and the user should know)."""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from ..errors import InputError
from .mesh import TriMesh


@dataclass
class MeshCheck:
    """What validation found and fixed. Counts refer to the mesh as loaded."""

    removed_degenerate_faces: int = 0
    removed_duplicate_faces: int = 0
    removed_unreferenced_vertices: int = 0
    triangulated_polygons: int = 0
    boundary_edges: int = 0
    holes: int = 0
    non_manifold_edges: int = 0
    watertight: bool = False

    def to_dict(self) -> dict:
        return asdict(self)


def edge_topology(faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Unique undirected edges (E, 2) int64 (sorted pairs) and how many faces use each (E,) int64."""
    e = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), axis=1)
    n = int(faces.max()) + 1
    keys, counts = np.unique(e[:, 0] * n + e[:, 1], return_counts=True)  # 1-D keys: much faster than axis=0
    return np.stack([keys // n, keys % n], axis=1), counts


def count_boundary_loops(boundary_edges: np.ndarray) -> int:
    """Number of connected loops formed by boundary edges (E, 2): the number of holes."""
    if len(boundary_edges) == 0:
        return 0
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    nodes, inv = np.unique(boundary_edges, return_inverse=True)
    inv = inv.reshape(-1, 2)
    n = len(nodes)
    g = coo_matrix((np.ones(len(inv)), (inv[:, 0], inv[:, 1])), shape=(n, n))
    n_comp, _ = connected_components(g, directed=False)
    return int(n_comp)


def clean_mesh(mesh: TriMesh, *, source: str | None = None) -> tuple[TriMesh, MeshCheck]:
    """Validate and clean a mesh; returns the cleaned copy and what was done.

    Raises InputError (naming `source`) if the mesh is empty or holds NaN/inf coordinates.
    Removes degenerate faces (repeated vertex or zero area), duplicate faces and unreferenced vertices.
    """
    check = MeshCheck()
    v, f = mesh.vertices, mesh.faces
    if len(v) == 0 or len(f) == 0:
        raise InputError("mesh is empty (no vertices or no faces)", source)
    if not np.isfinite(v).all():
        bad = int((~np.isfinite(v)).any(axis=1).sum())
        raise InputError(f"{bad} vertices have NaN or infinite coordinates", source)
    if f.min() < 0 or f.max() >= len(v):
        raise InputError("a face refers to a vertex that does not exist", source)
    # Degenerate: a repeated index, or an area negligible against the mesh scale.
    repeated = (f[:, 0] == f[:, 1]) | (f[:, 1] == f[:, 2]) | (f[:, 2] == f[:, 0])
    with np.errstate(over="ignore", invalid="ignore"):
        scale = float(np.ptp(v, axis=0).max()) or 1.0
    if not np.isfinite(scale) or scale > 1e150:  # cross products would overflow: no real mesh spans this
        raise InputError(f"coordinates span {scale:.3g} units, too large for any mesh", source)
    tri = v[f]
    area2 = np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    degenerate = repeated | (area2 <= (1e-12 * scale) ** 2)
    check.removed_degenerate_faces = int(degenerate.sum())
    f = f[~degenerate]
    if len(f) == 0:
        raise InputError("every face is degenerate (zero area)", source)
    # Duplicate faces (same three vertices in any order) are dropped, keeping the first.
    sf = np.sort(f, axis=1)
    n = len(v)
    if n < 2_000_000:  # n**3 fits in int64: one key per face
        _, first = np.unique((sf[:, 0] * n + sf[:, 1]) * n + sf[:, 2], return_index=True)
    else:
        _, first = np.unique(sf, axis=0, return_index=True)
    check.removed_duplicate_faces = len(f) - len(first)
    f = f[np.sort(first)]
    used = np.zeros(len(v), dtype=bool)
    used[f.ravel()] = True
    check.removed_unreferenced_vertices = int((~used).sum())
    remap = np.cumsum(used) - 1
    v = v[used]
    f = remap[f]
    uv = None if mesh.uv is None else mesh.uv[used]
    edges, counts = edge_topology(f)
    boundary = edges[counts == 1]
    check.boundary_edges = len(boundary)
    check.non_manifold_edges = int((counts > 2).sum())
    check.holes = count_boundary_loops(boundary)
    check.watertight = check.boundary_edges == 0 and check.non_manifold_edges == 0
    return TriMesh(v, f, uv, mesh.name, mesh.texture), check
