"""Simple cloth meshes for examples, tests and benchmarks: a flat grid sheet and a tube sewn from one."""

from __future__ import annotations

import numpy as np

from ..errors import InputError


def grid_sheet(nx: int, ny: int, spacing_m: float) -> tuple[np.ndarray, np.ndarray]:
    """A rectangular sheet of nx by ny vertices, `spacing_m` apart, triangulated with alternating diagonals.

    Returns rest_uv (nx * ny, 2) float64 metres (x along the row, y up the sheet; vertex j * nx + i at
    (i, j) * spacing) and faces (2 (nx - 1)(ny - 1), 3) int64, counter-clockwise in uv.
    """
    if nx < 2 or ny < 2 or not spacing_m > 0:
        raise InputError(f"a grid sheet needs nx, ny >= 2 and spacing > 0, got {nx}, {ny}, {spacing_m}")
    i, j = np.meshgrid(np.arange(nx), np.arange(ny))
    uv = np.stack([i.ravel(), j.ravel()], axis=1) * float(spacing_m)
    ci, cj = np.meshgrid(np.arange(nx - 1), np.arange(ny - 1))
    ci, cj = ci.ravel(), cj.ravel()
    v00, v10 = cj * nx + ci, cj * nx + ci + 1
    v01, v11 = v00 + nx, v10 + nx
    alt = (ci + cj) % 2 == 1  # alternate the diagonal so the sheet has no preferred shear direction
    f1 = np.where(alt[:, None], np.stack([v00, v10, v01], 1), np.stack([v00, v10, v11], 1))
    f2 = np.where(alt[:, None], np.stack([v10, v11, v01], 1), np.stack([v00, v11, v01], 1))
    return uv, np.concatenate([f1, f2]).astype(np.int64)


def grid_tube(n_around: int, n_rows: int, spacing_m: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A tube sewn from a grid sheet of (n_around + 1) by n_rows vertices: its last column is joined to its first
    (one seam, vertices shared).

    Returns faces (F, 3) int64 over n_around * n_rows vertices (vertex j * n_around + i), rest_corners (F, 3, 2)
    float64 metres (the sheet's pattern positions, so the seam's two sides keep their own), and rest_uv
    ((n_around + 1) * n_rows, 2) of the unsewn sheet.
    """
    if n_around < 3:
        raise InputError(f"a tube needs at least 3 vertices around, got {n_around}")
    uv, faces = grid_sheet(n_around + 1, n_rows, spacing_m)
    col, row = faces % (n_around + 1), faces // (n_around + 1)
    sewn = row * n_around + col % n_around
    return sewn.astype(np.int64), uv[faces], uv


def triangle_frames(positions: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Rest corners (F, 3, 2) metres that give each triangle its current 3D shape: corner 0 at the origin, corner 1
    on +x, corner 2 above (counter-clockwise). For cloth whose rest shape is its placed shape."""
    tri = np.asarray(positions, dtype=np.float64)[np.asarray(faces, dtype=np.int64)]
    e1, e2 = tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
    l1 = np.linalg.norm(e1, axis=1)
    x = e1 / np.maximum(l1, 1e-300)[:, None]
    ex = np.einsum("ij,ij->i", e2, x)
    ey = np.linalg.norm(e2 - ex[:, None] * x, axis=1)
    out = np.zeros((len(tri), 3, 2))
    out[:, 1, 0] = l1
    out[:, 2, 0], out[:, 2, 1] = ex, ey
    return out


def hugging_tube(
    body_vertices: np.ndarray,
    y_bottom: float,
    y_top: float,
    n_around: int,
    n_rows: int,
    *,
    offset_m: float = 0.005,
    centre_xz: tuple[float, float] = (0.0, 0.0),
    max_radius_m: float = 0.35,
    band_m: float = 0.03,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A closed tube around a body between two heights, each ring just outside the body's slice there (the
    slice's support function in each direction plus `offset_m`); its rest shape is its own shape.

    The slice at height y is the body vertices within `band_m` of y and within `max_radius_m` of the vertical
    axis through `centre_xz` (so that hands hanging beside the hips are left out).

    Returns positions (n_around * n_rows, 3) metres (vertex j * n_around + i: ring j from the bottom, i around),
    faces (F, 3) int64 wound outwards, rest_corners (F, 3, 2) metres (`triangle_frames`).
    """
    v = np.asarray(body_vertices, dtype=np.float64)
    theta = 2 * np.pi * np.arange(n_around) / n_around
    dirs = np.stack([np.sin(theta), np.cos(theta)], axis=1)  # x, z: angle 0 faces +Z, increasing towards +X
    ys = np.linspace(y_bottom, y_top, n_rows)
    cx, cz = centre_xz
    v = v[np.hypot(v[:, 0] - cx, v[:, 2] - cz) <= max_radius_m]
    rings = []
    for y in ys:
        sl = v[np.abs(v[:, 1] - y) <= band_m]
        if len(sl) == 0:
            raise InputError(f"the body has no surface at height {y:.3f} m")
        h = ((sl[:, [0, 2]] - (cx, cz)) @ dirs.T).max(axis=0) + offset_m
        rings.append(np.stack([cx + h * dirs[:, 0], np.full(n_around, y), cz + h * dirs[:, 1]], axis=1))
    pos = np.concatenate(rings)
    faces, _, _ = grid_tube(n_around, n_rows, 1.0)
    return pos, faces, triangle_frames(pos, faces)
