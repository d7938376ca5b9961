"""Surface queries on a triangle mesh: closest points, ray hits, barycentric coordinates.

`Surface` wraps a `TriMesh` and builds its acceleration structures once, on first use:

- closest points through libigl's AABB tree (`igl.AABB`). This is exact and fast for points at any distance;
  `trimesh.proximity.closest_point` is not used: it exhausts memory on points far from the mesh (SPEC §8).
- rays through trimesh's embree intersector (`embreex`), every hit along each ray; a plain-numpy trimesh
  intersector stands in when embreex is missing (same answers, much slower).

Every answer is a `SurfacePoints`: the point, the face it lies on and its barycentric coordinates in that
face, so callers can follow the point when the mesh moves (a posed body, a garment being relaxed).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np

from .mesh import TriMesh

RayHit = Literal["first", "last"]


@dataclass
class SurfacePoints:
    """Points on a mesh surface.

    Attributes
    ----------
    points : (n, 3) float64, metres, on the surface (NaN where a ray missed).
    faces : (n,) int64, the face each point lies on (-1 where a ray missed).
    barycentric : (n, 3) float64, weights of the face's three corners (non-negative, summing to 1; NaN on a
        miss).
    distance : (n,) float64, metres: from the query point to the surface point (closest-point queries), or
        along the unit ray direction from its origin (ray queries; NaN on a miss).
    """

    points: np.ndarray
    faces: np.ndarray
    barycentric: np.ndarray
    distance: np.ndarray

    def __post_init__(self) -> None:
        self.points = np.ascontiguousarray(self.points, dtype=np.float64).reshape(-1, 3)
        self.faces = np.ascontiguousarray(self.faces, dtype=np.int64).reshape(-1)
        self.barycentric = np.ascontiguousarray(self.barycentric, dtype=np.float64).reshape(-1, 3)
        self.distance = np.ascontiguousarray(self.distance, dtype=np.float64).reshape(-1)
        n = len(self.points)
        if not (len(self.faces) == len(self.barycentric) == len(self.distance) == n):
            raise ValueError("SurfacePoints arrays must have the same length")

    def __len__(self) -> int:
        return len(self.points)

    @property
    def hit(self) -> np.ndarray:
        """(n,) bool: the points that exist (a ray that missed has none)."""
        return self.faces >= 0

    def take(self, index: np.ndarray) -> SurfacePoints:
        """The subset (or reordering) `index` (an int or bool array)."""
        return SurfacePoints(self.points[index], self.faces[index], self.barycentric[index], self.distance[index])

    @staticmethod
    def empty() -> SurfacePoints:
        return SurfacePoints(np.zeros((0, 3)), np.zeros(0, np.int64), np.zeros((0, 3)), np.zeros(0))


def barycentric_coordinates(triangles: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Barycentric coordinates (n, 3) of points (n, 3) in triangles (n, 3, 3).

    Points off the triangle's plane get the coordinates of their projection onto it. Coordinates are clipped
    to be non-negative and renormalised: meant for points on (or, by round-off, next to) the triangle, such
    as closest points and ray hits. Degenerate triangles give (1, 0, 0).
    """
    tri = np.asarray(triangles, dtype=np.float64).reshape(-1, 3, 3)
    p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    a = tri[:, 0]
    e1, e2, d = tri[:, 1] - a, tri[:, 2] - a, p - a
    d11 = np.einsum("ij,ij->i", e1, e1)
    d12 = np.einsum("ij,ij->i", e1, e2)
    d22 = np.einsum("ij,ij->i", e2, e2)
    dp1 = np.einsum("ij,ij->i", d, e1)
    dp2 = np.einsum("ij,ij->i", d, e2)
    den = d11 * d22 - d12 * d12
    ok = den > 1e-30 * np.maximum(d11 * d22, 1e-300)
    safe = np.where(ok, den, 1.0)
    v = np.where(ok, (d22 * dp1 - d12 * dp2) / safe, 0.0)
    w = np.where(ok, (d11 * dp2 - d12 * dp1) / safe, 0.0)
    bary = np.clip(np.stack([1.0 - v - w, v, w], axis=-1), 0.0, None)
    return bary / np.maximum(bary.sum(axis=1, keepdims=True), 1e-300)


class Surface:
    """Closest-point and ray queries on one triangle mesh (built lazily, reused across queries).

    Parameters
    ----------
    mesh : the surface (TriMesh, metres). Its arrays are not copied: do not change them while the Surface is
        used (make a new Surface for moved vertices).
    """

    def __init__(self, mesh: TriMesh):
        self.mesh = mesh
        self._aabb = None
        self._rays = None

    @staticmethod
    def of(mesh: TriMesh | Surface) -> Surface:
        """`mesh` itself if it is a Surface, else a new Surface on it."""
        return mesh if isinstance(mesh, Surface) else Surface(mesh)

    @property
    def vertices(self) -> np.ndarray:
        """(V, 3) float64, metres."""
        return self.mesh.vertices

    @property
    def faces(self) -> np.ndarray:
        """(F, 3) int64."""
        return self.mesh.faces

    # -- closest points --------------------------------------------------------------------------------------
    def closest(self, points: np.ndarray) -> SurfacePoints:
        """The closest surface point to each of `points` (n, 3) metres, any distance away (libigl AABB)."""
        face, point, distance = self.nearest(points)
        if len(face) == 0:
            return SurfacePoints.empty()
        bary = barycentric_coordinates(self.vertices[self.faces[face]], point)
        return SurfacePoints(point, face, bary, distance)

    def nearest(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """`closest` without the barycentric coordinates (what collision needs, many times per wrap): face (n,)
        int64, point (n, 3) metres, distance (n,) metres."""
        pts = np.ascontiguousarray(points, dtype=np.float64).reshape(-1, 3)
        if len(pts) == 0:
            return np.zeros(0, dtype=np.int64), np.zeros((0, 3)), np.zeros(0)
        if not np.isfinite(pts).all():
            raise ValueError("surface query: points hold NaN or infinity")
        if self._aabb is None:
            import igl

            self._aabb = igl.AABB()
            self._aabb.init(self.vertices, self.faces)
        d2, face, point = self._aabb.squared_distance(self.vertices, self.faces, pts)
        return face.astype(np.int64), point, np.sqrt(np.maximum(d2, 0.0))

    # -- rays ------------------------------------------------------------------------------------------------
    def _intersector(self):
        if self._rays is None:
            import trimesh

            tm = trimesh.Trimesh(self.vertices, self.faces, process=False, validate=False)
            try:
                from trimesh.ray.ray_pyembree import RayMeshIntersector
            except ImportError:  # embreex missing: the pure-numpy intersector gives the same hits, slower
                from trimesh.ray.ray_triangle import RayMeshIntersector
            self._rays = RayMeshIntersector(tm)
        return self._rays

    def ray_hits(self, origins: np.ndarray, directions: np.ndarray) -> tuple[np.ndarray, SurfacePoints]:
        """Every hit of every ray in front of its origin.

        origins, directions : (n, 3) float64, metres; directions need not be unit length but must not be zero.
        Returns (ray (h,) int64 — which ray each hit belongs to —, hits SurfacePoints (h,) with `distance` the
        distance from the ray's origin), sorted by ray then distance.
        """
        o = np.ascontiguousarray(origins, dtype=np.float64).reshape(-1, 3)
        d = np.ascontiguousarray(directions, dtype=np.float64).reshape(-1, 3)
        if len(o) != len(d):
            raise ValueError(f"ray_hits: {len(o)} origins but {len(d)} directions")
        if not (np.isfinite(o).all() and np.isfinite(d).all()):
            raise ValueError("ray_hits: rays hold NaN or infinity")
        norm = np.linalg.norm(d, axis=1)
        if (norm <= 0).any():
            raise ValueError("ray_hits: a ray direction is zero")
        d = d / norm[:, None]
        if len(o) == 0:
            return np.zeros(0, np.int64), SurfacePoints.empty()
        loc, ray, face = self._intersector().intersects_location(o, d, multiple_hits=True)
        ray = np.asarray(ray, dtype=np.int64)
        face = np.asarray(face, dtype=np.int64)
        loc = np.asarray(loc, dtype=np.float64).reshape(-1, 3)
        t = np.einsum("ij,ij->i", loc - o[ray], d[ray])
        # Recompute each hit exactly on its ray in float64 (embree reports single-precision distances).
        loc = o[ray] + t[:, None] * d[ray]
        order = np.lexsort((t, ray))
        ray, face, loc, t = ray[order], face[order], loc[order], t[order]
        bary = barycentric_coordinates(self.vertices[self.faces[face]], loc)
        return ray, SurfacePoints(loc, face, bary, t)

    def cast(self, origins: np.ndarray, directions: np.ndarray, *, hit: RayHit = "first") -> SurfacePoints:
        """One hit per ray: the nearest (`hit="first"`, the surface facing the origin) or the farthest
        (`"last"`, the far side: the paper's laser mode draws both). Rays that miss get face -1 and NaN (see
        `.hit`).

        origins, directions : (n, 3) float64, metres (directions non-zero, any length).
        """
        if hit not in ("first", "last"):
            raise ValueError(f"hit must be 'first' or 'last', got {hit!r}")
        o = np.asarray(origins, dtype=np.float64).reshape(-1, 3)
        ray, hits = self.ray_hits(o, directions)
        n = len(o)
        out = SurfacePoints(
            np.full((n, 3), np.nan), np.full(n, -1, np.int64), np.full((n, 3), np.nan), np.full(n, np.nan)
        )
        if len(ray):
            # Hits are sorted by ray then distance: the first/last row of each ray's run.
            starts = np.flatnonzero(np.r_[True, ray[1:] != ray[:-1]])
            ends = np.r_[starts[1:], len(ray)] - 1
            pick = starts if hit == "first" else ends
            sel = hits.take(pick)
            idx = ray[pick]
            out.points[idx], out.faces[idx] = sel.points, sel.faces
            out.barycentric[idx], out.distance[idx] = sel.barycentric, sel.distance
        return out

    # -- evaluation ------------------------------------------------------------------------------------------
    def evaluate(self, faces: np.ndarray, barycentric: np.ndarray, vertices: np.ndarray | None = None) -> np.ndarray:
        """Points (n, 3) at barycentric coordinates (n, 3) in faces (n,) — of `vertices` (V, 3) if given (the
        same mesh moved, e.g. posed), else of this surface."""
        v = self.vertices if vertices is None else np.asarray(vertices, dtype=np.float64)
        f = np.asarray(faces, dtype=np.int64).reshape(-1)
        b = np.asarray(barycentric, dtype=np.float64).reshape(-1, 3)
        return np.einsum("ij,ijk->ik", b, v[self.faces[f]])

    def normals_at(self, faces: np.ndarray) -> np.ndarray:
        """Unit face normals (n, 3) of `faces` (n,), pointing outwards for a counter-clockwise mesh."""
        f = np.asarray(faces, dtype=np.int64).reshape(-1)
        tri = self.vertices[self.faces[f]]
        n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
        length = np.linalg.norm(n, axis=1, keepdims=True)
        return np.divide(n, length, out=np.zeros_like(n), where=length > 0)
