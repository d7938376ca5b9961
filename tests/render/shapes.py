"""Small procedural meshes (trimesh primitives) and image measurements for the render tests."""

from __future__ import annotations

import numpy as np
import trimesh

from kitsuke.geometry import TriMesh

#: Solid background used where a test separates the subject from the background by colour.
BG = (0.0, 1.0, 0.0)


def box(width: float = 0.4, height: float = 1.7, depth: float = 0.2, *, y0: float = 0.0) -> TriMesh:
    """Axis-aligned box standing on y = y0: width along X, height along Y, depth along Z (metres)."""
    m = trimesh.creation.box(extents=(width, height, depth))
    return TriMesh(m.vertices + [0.0, y0 + height / 2, 0.0], m.faces, name="box")


def sphere(radius: float = 0.5, center=(0.0, 0.0, 0.0), subdivisions: int = 3, name: str = "sphere") -> TriMesh:
    m = trimesh.creation.icosphere(subdivisions=subdivisions, radius=radius)
    return TriMesh(m.vertices + np.asarray(center), m.faces, name=name)


def quad(size: float = 1.0, *, uv_repeat: float = 1.0) -> TriMesh:
    """A single-sided square in the XY plane at z = 0, facing +Z (counter-clockwise seen from +Z), with UVs."""
    h = size / 2
    v = np.array([[-h, -h, 0.0], [h, -h, 0.0], [h, h, 0.0], [-h, h, 0.0]])
    uv = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]) * uv_repeat
    return TriMesh(v, np.array([[0, 1, 2], [0, 2, 3]]), uv=uv, name="quad")


def checker(n: int = 8, px: int = 16, a=(220, 30, 30), b=(30, 30, 220)) -> np.ndarray:
    """(n*px, n*px, 3) uint8 checkerboard of colours a and b."""
    cells = (np.add.outer(np.arange(n * px) // px, np.arange(n * px) // px) % 2).astype(bool)
    img = np.empty((n * px, n * px, 3), np.uint8)
    img[cells], img[~cells] = a, b
    return img


def subject_mask(image: np.ndarray, bg=BG, tol: int = 6) -> np.ndarray:
    """(H, W) bool: pixels that differ from the solid background (RGB) or are not fully transparent (RGBA)."""
    if image.shape[2] == 4:
        return image[..., 3] > 0
    ref = np.rint(np.asarray(bg) * 255).astype(int)
    return np.abs(image.astype(int) - ref).max(axis=2) > tol


def mask_bbox(mask: np.ndarray) -> tuple[int, int, int, int]:
    """(x0, y0, x1, y1) inclusive pixel bounds of a non-empty mask."""
    ys, xs = np.nonzero(mask)
    return int(xs.min()), int(ys.min()), int(xs.max()), int(ys.max())


def luminance(rgb: np.ndarray) -> np.ndarray:
    return rgb[..., :3].astype(np.float64) @ np.array([0.2126, 0.7152, 0.0722])
