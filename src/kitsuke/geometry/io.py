"""Loading and saving meshes: OBJ (our reader), GLB/glTF, PLY, STL, OFF (trimesh). Saves are atomic."""

from __future__ import annotations

import io as _io
from pathlib import Path

import numpy as np

from .. import limits
from .._files import atomic_path, require_file
from ..errors import InputError
from .gltf import static_glb
from .mesh import TriMesh
from .obj import read_obj

MESH_SUFFIXES = (".obj", ".glb", ".gltf", ".ply", ".stl", ".off")


def load_mesh(path: str | Path, *, group: str | None = None) -> TriMesh:
    """Read a triangle mesh as it is in the file (units and axes untouched), validated and cleaned.

    Raises InputError naming the file for a missing, empty, unreadable or unsupported file, NaN coordinates or no
    faces. Degenerate faces and unreferenced vertices are dropped (see `validate.clean_mesh`).
    """
    from .validate import clean_mesh

    mesh, _ = read_mesh(path, group=group)
    return clean_mesh(mesh, source=str(path))[0]


def read_mesh(path: str | Path, *, group: str | None = None) -> tuple[TriMesh, int]:
    """Read a triangle mesh in file units and axes (no cleaning, no conversion).

    Returns the mesh and how many polygons were split into triangles. `group` keeps only the faces of one OBJ group.
    Raises InputError naming the file for a missing, empty, unreadable or unsupported file.
    """
    p = require_file(path, what="mesh file")
    suffix = p.suffix.lower()
    if suffix not in MESH_SUFFIXES:
        raise InputError(f"unsupported mesh format {suffix!r}; use one of {', '.join(MESH_SUFFIXES)}", p)
    if suffix == ".obj":
        data = read_obj(p)
        if group is not None and group not in data.groups:
            raise InputError(f"no group {group!r}; groups are: {', '.join(data.groups)}", p)
        keep = np.ones(len(data.faces), bool) if group is None else data.face_group == data.groups.index(group)
        faces = data.faces[keep]
        uv = None
        if data.uv is not None and data.face_uv is not None and (data.face_uv[keep] >= 0).all():
            # One uv per vertex, from the last corner that names it (UV seams only matter for texturing).
            uv = np.zeros((len(data.vertices), 2))
            uv[faces.ravel()] = data.uv[data.face_uv[keep].ravel()]
        return TriMesh(data.vertices, faces, uv, name=p.stem), data.polygons_triangulated
    if group is not None:
        raise InputError("groups can be selected in OBJ files only", p)
    return _load_with_trimesh(p), 0


def _load_with_trimesh(p: Path) -> TriMesh:
    import trimesh

    try:
        # process=False: keep the file's vertices; cleaning is ours (validate.clean_mesh) and is reported.
        loaded = trimesh.load(p, force="mesh", process=False)
    except Exception as e:  # noqa: BLE001 - trimesh raises many types for corrupt files
        raise InputError(f"cannot read as {p.suffix[1:].upper()}: {e}", p) from None
    if not isinstance(loaded, trimesh.Trimesh) or len(loaded.vertices) == 0 or len(loaded.faces) == 0:
        raise InputError("holds no triangle mesh (point cloud or empty scene?)", p)
    limits.check("vertices", len(loaded.vertices), f"the file has {len(loaded.vertices):,} vertices", p)
    limits.check("triangles", len(loaded.faces), f"the file has {len(loaded.faces):,} triangles", p)
    faces = np.asarray(loaded.faces)
    if faces.min() < 0 or faces.max() >= len(loaded.vertices):
        raise InputError("a face refers to a vertex that does not exist", p)
    if not np.isfinite(np.asarray(loaded.vertices, dtype=np.float64)).all():
        raise InputError("vertices have NaN or infinite coordinates", p)
    # glTF splits vertices along UV/normal seams, which opens the surface: if it is open, merge coincident
    # positions so it is one piece again (a closed mesh is left exactly as stored).
    if p.suffix.lower() in (".glb", ".gltf") and not loaded.is_watertight:
        loaded.merge_vertices(merge_tex=True, merge_norm=True)
    uv = None
    visual = getattr(loaded, "visual", None)
    if visual is not None and getattr(visual, "uv", None) is not None and len(visual.uv) == len(loaded.vertices):
        uv = np.asarray(visual.uv, dtype=np.float64)
    return TriMesh(np.asarray(loaded.vertices), np.asarray(loaded.faces), uv, name=p.stem)


def save_mesh(mesh: TriMesh | list[TriMesh], path: str | Path) -> Path:
    """Write one or more meshes to OBJ, GLB or PLY (by suffix), atomically. GLB keeps names, UVs and textures."""
    meshes = mesh if isinstance(mesh, list) else [mesh]
    p = Path(path)
    suffix = p.suffix.lower()
    if suffix not in (".obj", ".glb", ".ply"):
        raise InputError("output must end in .obj, .glb or .ply", p)
    if suffix == ".obj":
        data = _obj_text(meshes).encode()
    elif suffix == ".glb":
        data = static_glb(meshes)
    else:
        import trimesh

        data = trimesh.util.concatenate([_to_trimesh(m) for m in meshes]).export(file_type="ply")
    with atomic_path(p) as tmp:
        tmp.write_bytes(data)
    return p


def _to_trimesh(m: TriMesh):
    import trimesh
    from PIL import Image

    visual = None
    if m.uv is not None:
        image = Image.fromarray(m.texture) if m.texture is not None else None
        material = trimesh.visual.material.PBRMaterial(
            baseColorTexture=image,
            baseColorFactor=[255, 255, 255, 255],
            doubleSided=True,
            roughnessFactor=0.9,
        )
        visual = trimesh.visual.TextureVisuals(uv=m.uv, material=material)
    return trimesh.Trimesh(m.vertices, m.faces, visual=visual, process=False)


def _obj_text(meshes: list[TriMesh]) -> str:
    out = _io.StringIO()
    out.write("# written by kitsuke\n")
    offset = uv_offset = 0
    for m in meshes:
        out.write(f"o {m.name}\n")
        np.savetxt(out, m.vertices, fmt="v %.7g %.7g %.7g")
        if m.uv is not None:
            np.savetxt(out, m.uv, fmt="vt %.7g %.7g")
            corners = np.stack([m.faces + 1 + offset, m.faces + 1 + uv_offset], axis=2).reshape(-1, 6)
            np.savetxt(out, corners, fmt="f %d/%d %d/%d %d/%d")
            uv_offset += len(m.uv)
        else:
            np.savetxt(out, m.faces + 1 + offset, fmt="f %d %d %d")
        offset += len(m.vertices)
    return out.getvalue()
