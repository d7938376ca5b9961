"""A small, strict Wavefront OBJ reader for positions, faces, groups and texture coordinates.

Why our own: trimesh splits vertices along UV seams when it keeps UVs, which turns a closed body into many islands,
and it cannot keep one named group. Here positions stay shared, polygons are fan-triangulated, and every face
remembers its group and its per-corner `vt`.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import InputError


@dataclass
class ObjData:
    """What an OBJ file holds, triangulated.

    vertices : (V, 3) float64, file units.
    faces : (F, 3) int64, 0-based vertex indices.
    face_uv : (F, 3) int64 or None, 0-based indices into `uv` per corner (-1 where a corner has no vt).
    uv : (T, 2) float64 or None.
    face_group : (F,) int64, index into `groups`.
    groups : list of group names (`g` or `o` lines; "default" before any).
    polygons_triangulated : number of faces with more than 3 corners that were split into triangles.
    comments : the file's comment lines, without the leading '#'.
    """

    vertices: np.ndarray
    faces: np.ndarray
    face_uv: np.ndarray | None
    uv: np.ndarray | None
    face_group: np.ndarray
    groups: list[str]
    polygons_triangulated: int
    comments: list[str]


def read_obj(path: str | Path) -> ObjData:
    """Parse an OBJ file. Raises InputError naming the file and line for anything malformed."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8", errors="replace")
    except OSError as e:
        raise InputError(f"cannot read: {e.strerror}", path) from None
    verts: list[str] = []
    uvs: list[str] = []
    tris: list[tuple[int, int, int]] = []
    tri_uv: list[tuple[int, int, int]] = []
    tri_group: list[int] = []
    groups = ["default"]
    group = 0
    n_poly = 0
    comments: list[str] = []
    for lineno, raw in enumerate(text.splitlines(), start=1):
        line = raw.strip()
        if not line:
            continue
        if line[0] == "#":
            comments.append(line[1:].strip())
            continue
        tag, _, rest = line.partition(" ")
        if tag == "v":
            verts.append(rest)
        elif tag == "vt":
            uvs.append(rest)
        elif tag in ("g", "o"):
            name = rest.strip() or "default"
            if name not in groups:
                groups.append(name)
            group = groups.index(name)
        elif tag == "f":
            corners = rest.split()
            if len(corners) < 3:
                raise InputError(f"line {lineno}: a face needs at least 3 corners", path)
            try:
                vi, ti = [], []
                for c in corners:
                    parts = c.split("/")
                    v = int(parts[0])
                    vi.append(v - 1 if v > 0 else len(verts) + v)
                    if len(parts) > 1 and parts[1]:
                        t = int(parts[1])
                        ti.append(t - 1 if t > 0 else len(uvs) + t)
                    else:
                        ti.append(-1)
            except ValueError:
                raise InputError(f"line {lineno}: bad face index in {line!r}", path) from None
            if len(corners) > 3:
                n_poly += 1
            for k in range(1, len(vi) - 1):  # fan triangulation (OBJ polygons are convex by convention)
                tris.append((vi[0], vi[k], vi[k + 1]))
                tri_uv.append((ti[0], ti[k], ti[k + 1]))
                tri_group.append(group)
    if not verts:
        raise InputError("no vertices (is this an OBJ file?)", path)
    try:
        flat = " ".join(verts).split()
        if len(flat) == 3 * len(verts):  # the usual case: x y z only, parsed in one go
            vertices = np.array(flat, dtype=np.float64).reshape(-1, 3)
        else:  # some lines carry w or vertex colours
            vertices = np.array([r.split()[:3] for r in verts], dtype=np.float64)
    except ValueError:
        raise InputError("a 'v' line does not hold three numbers", path) from None
    if vertices.ndim != 2 or vertices.shape[1] != 3:
        raise InputError("a 'v' line does not hold three numbers", path)
    faces = np.array(tris, dtype=np.int64).reshape(-1, 3)
    if len(faces) and (faces.min() < 0 or faces.max() >= len(vertices)):
        raise InputError(f"a face refers to a vertex that does not exist (file has {len(vertices)})", path)
    uv = face_uv = None
    if uvs:
        try:
            uv = np.array([r.split()[:2] for r in uvs], dtype=np.float64)
        except ValueError:
            raise InputError("a 'vt' line does not hold two numbers", path) from None
        face_uv = np.array(tri_uv, dtype=np.int64).reshape(-1, 3)
        if len(face_uv) and face_uv.max() >= len(uv):
            raise InputError("a face refers to a texture coordinate that does not exist", path)
    return ObjData(vertices, faces, face_uv, uv, np.array(tri_group, dtype=np.int64), groups, n_poly, comments)
