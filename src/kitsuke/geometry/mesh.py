"""The triangle mesh type every part of kitsuke passes around."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass
class TriMesh:
    """A triangle mesh.

    Attributes
    ----------
    vertices : (V, 3) float64, metres, world frame (Y up, facing +Z).
    faces : (F, 3) int64, vertex indices, counter-clockwise seen from outside.
    uv : (V, 2) float64 or None, texture coordinates in [0, 1] (per vertex).
    name : a label used in exports and reports.
    texture : (H, W, 3 or 4) uint8 image or None, sampled through `uv`.
    """

    vertices: np.ndarray
    faces: np.ndarray
    uv: np.ndarray | None = None
    name: str = "mesh"
    texture: np.ndarray | None = field(default=None, repr=False)

    def __post_init__(self) -> None:
        self.vertices = np.ascontiguousarray(self.vertices, dtype=np.float64).reshape(-1, 3)
        self.faces = np.ascontiguousarray(self.faces, dtype=np.int64).reshape(-1, 3)
        if self.uv is not None:
            self.uv = np.ascontiguousarray(self.uv, dtype=np.float64).reshape(-1, 2)
            if len(self.uv) != len(self.vertices):
                raise ValueError(f"uv has {len(self.uv)} rows for {len(self.vertices)} vertices")

    @property
    def n_vertices(self) -> int:
        return len(self.vertices)

    @property
    def n_faces(self) -> int:
        return len(self.faces)

    @property
    def bounds(self) -> np.ndarray:
        """(2, 3) float64: min and max corner of the bounding box, metres."""
        return np.stack([self.vertices.min(axis=0), self.vertices.max(axis=0)])

    @property
    def face_normals(self) -> np.ndarray:
        """(F, 3) float64 unit normals (zero for degenerate faces)."""
        tri = self.vertices[self.faces]
        n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
        length = np.linalg.norm(n, axis=1, keepdims=True)
        return np.divide(n, length, out=np.zeros_like(n), where=length > 0)

    @property
    def face_areas(self) -> np.ndarray:
        """(F,) float64, square metres."""
        tri = self.vertices[self.faces]
        return 0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)

    @property
    def vertex_normals(self) -> np.ndarray:
        """(V, 3) float64 area-weighted unit vertex normals (zero for unreferenced vertices)."""
        tri = self.vertices[self.faces]
        fn = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])  # length = 2 * area: area weighting
        idx = self.faces.ravel()
        n = len(self.vertices)
        # bincount per axis: much faster than np.add.at (a render computes this every frame)
        vn = np.stack([np.bincount(idx, weights=np.repeat(fn[:, k], 3), minlength=n) for k in range(3)], axis=1)
        length = np.linalg.norm(vn, axis=1, keepdims=True)
        return np.divide(vn, length, out=np.zeros_like(vn), where=length > 0)

    def copy(self) -> TriMesh:
        return TriMesh(
            self.vertices.copy(),
            self.faces.copy(),
            None if self.uv is None else self.uv.copy(),
            self.name,
            self.texture,
        )
