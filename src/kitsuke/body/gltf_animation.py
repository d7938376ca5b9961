"""An animated, skinned GLB of a body (glTF 2.0, written here: trimesh writes no skins or animations).

One mesh skinned to the 23 joints of `kitsuke.skeleton` (four weights per vertex, the largest, renormalised: what
glTF viewers and three.js read), the joints as a node tree whose rest pose is the body's (every joint's rest
orientation is the world's, so a node's translation is its rest bone), and one animation: each joint's rotation
relative to its parent and the root's translation, per frame, linearly interpolated (quaternions slerped).

Optionally a second mesh that moves by itself (a simulated garment, `MorphMesh`): one morph target per frame
(positions and normals as offsets from its first frame), and the same animation sets the weights so that frame k
shows target k fully, linearly blended in between. Blender imports the targets as shape keys with their animation,
and three.js plays them (morph targets kept in a texture, so their number has no small limit).
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._files import atomic_path
from ..geometry import TriMesh
from ..geometry.gltf import (
    ARRAY_BUFFER,
    ELEMENT_ARRAY_BUFFER,
    FLOAT,
    UINT,
    USHORT,
    GltfBuffer,
    glb_bytes,
    vertex_normals,
)
from ..skeleton import JOINTS, PARENT_INDEX
from .animate import BodyAnimation


@dataclass
class MorphMesh:
    """A mesh whose vertices move by themselves over an animation's frames.

    mesh : its first frame (a TriMesh; `uv` and `texture` make it textured, the texture repeating outside [0, 1]).
    frames : (n, V, 3) float32 positions per frame, metres, n = the animation's frames.
    """

    mesh: TriMesh
    frames: np.ndarray


def _quaternions(rotations: np.ndarray) -> np.ndarray:
    """(n, 4) xyzw quaternions of (n, 3, 3) rotations, each on the same hemisphere as the one before (so that
    interpolating between frames takes the short way)."""
    from scipy.spatial.transform import Rotation

    q = Rotation.from_matrix(rotations).as_quat()
    for i in range(1, len(q)):
        if q[i] @ q[i - 1] < 0:
            q[i] = -q[i]
    return q


def _top4(weights: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(V, 4) joint indices and (V, 4) weights: each vertex's four largest, renormalised to sum to 1."""
    idx = np.argsort(-weights, axis=1)[:, :4]
    w = np.take_along_axis(weights, idx, axis=1)
    w /= w.sum(axis=1, keepdims=True)
    return idx.astype(np.uint16), w


def animated_glb(body, animation: BodyAnimation, cloth: MorphMesh | None = None) -> bytes:  # noqa: ANN001 - a rigged Body
    """The GLB bytes of `body` skinned and moved by `animation`, and `cloth` moving with it (optional)."""
    mesh, rig = body.mesh, body.rig
    buf = GltfBuffer()
    normals = vertex_normals(mesh.vertices, mesh.faces)
    joints4, weights4 = _top4(animation.weights)
    attributes = {
        "POSITION": buf.add(mesh.vertices, "VEC3", FLOAT, target=ARRAY_BUFFER, bounds=True),
        "NORMAL": buf.add(normals, "VEC3", FLOAT, target=ARRAY_BUFFER),
        "JOINTS_0": buf.add(joints4, "VEC4", USHORT, target=ARRAY_BUFFER),
        "WEIGHTS_0": buf.add(weights4, "VEC4", FLOAT, target=ARRAY_BUFFER),
    }
    if mesh.uv is not None:
        attributes["TEXCOORD_0"] = buf.add_uv(mesh.uv)
    indices = buf.add(mesh.faces.reshape(-1), "SCALAR", UINT, target=ELEMENT_ARRAY_BUFFER)
    # inverse bind matrices: the joints' rest frames are translations only (column-major 4x4)
    ibm = np.tile(np.eye(4), (len(JOINTS), 1, 1))
    ibm[:, :3, 3] = -rig.joints
    ibm_acc = buf.add(ibm.transpose(0, 2, 1).reshape(len(JOINTS), 16), "MAT4", FLOAT)

    first_joint = 1  # node 0 is the skinned mesh
    nodes: list[dict] = [{"name": "body", "mesh": 0, "skin": 0}]
    for j, name in enumerate(JOINTS):
        p = PARENT_INDEX[j]
        offset = rig.joints[j] - (rig.joints[p] if p >= 0 else 0.0)
        node: dict = {"name": name, "translation": [float(x) for x in offset]}
        kids = [first_joint + k for k in range(len(JOINTS)) if PARENT_INDEX[k] == j]
        if kids:
            node["children"] = kids
        nodes.append(node)

    times = buf.add(animation.times - animation.times[0], "SCALAR", FLOAT, bounds=True)
    local = animation.local_rotations
    samplers, channels = [], []
    for j in range(len(JOINTS)):
        out = buf.add(_quaternions(local[:, j]), "VEC4", FLOAT)
        samplers.append({"input": times, "output": out, "interpolation": "LINEAR"})
        channels.append({"sampler": len(samplers) - 1, "target": {"node": first_joint + j, "path": "rotation"}})
    root = buf.add(animation.joints[:, 0], "VEC3", FLOAT)
    samplers.append({"input": times, "output": root, "interpolation": "LINEAR"})
    channels.append({"sampler": len(samplers) - 1, "target": {"node": first_joint, "path": "translation"}})

    meshes = [{"name": "body", "primitives": [{"attributes": attributes, "indices": indices, "material": 0}]}]
    materials = [
        {
            "name": "skin",
            "pbrMetallicRoughness": {"baseColorFactor": [0.85, 0.72, 0.62, 1.0], "metallicFactor": 0.0},
            "doubleSided": False,
        }
    ]
    doc: dict = {}
    roots = [0, first_joint]
    if cloth is not None:
        if cloth.frames.shape[0] != animation.n_frames or cloth.frames.shape[1:] != cloth.mesh.vertices.shape:
            raise ValueError("the cloth needs one (V, 3) frame per animation frame")
        roots.append(len(nodes))
        nodes.append({"name": cloth.mesh.name or "cloth", "mesh": 1})
        _add_morph_mesh(buf, doc, meshes, materials, cloth)
        weights = buf.add(np.eye(animation.n_frames, dtype=np.float32).reshape(-1), "SCALAR", FLOAT)
        samplers.append({"input": times, "output": weights, "interpolation": "LINEAR"})
        channels.append({"sampler": len(samplers) - 1, "target": {"node": roots[-1], "path": "weights"}})

    doc |= {
        "asset": {"version": "2.0", "generator": "kitsuke"},
        "scene": 0,
        "scenes": [{"nodes": roots}],
        "nodes": nodes,
        "meshes": meshes,
        "materials": materials,
        "skins": [
            {
                "joints": list(range(first_joint, first_joint + len(JOINTS))),
                "inverseBindMatrices": ibm_acc,
                "skeleton": first_joint,
            }
        ],
        "animations": [{"name": "motion", "samplers": samplers, "channels": channels}],
        "buffers": [{"byteLength": len(buf.data)}],
        "bufferViews": buf.views,
        "accessors": buf.accessors,
    }
    return glb_bytes(doc, bytes(buf.data))


def _add_morph_mesh(buf: GltfBuffer, doc: dict, meshes: list, materials: list, cloth: MorphMesh) -> None:
    """Append the cloth's mesh (one morph target per frame) and its material (textured if it has one)."""
    mesh = cloth.mesh
    base = np.asarray(cloth.frames[0], dtype=np.float64)
    base_n = vertex_normals(base, mesh.faces)
    attributes = {
        "POSITION": buf.add(base, "VEC3", FLOAT, target=ARRAY_BUFFER, bounds=True),
        "NORMAL": buf.add(base_n, "VEC3", FLOAT, target=ARRAY_BUFFER),
    }
    material: dict = {
        "name": mesh.name or "cloth",
        "pbrMetallicRoughness": {"baseColorFactor": [0.55, 0.6, 0.8, 1.0], "metallicFactor": 0.0},
        "doubleSided": True,
    }
    if mesh.uv is not None:
        attributes["TEXCOORD_0"] = buf.add_uv(mesh.uv)
    if mesh.uv is not None and mesh.texture is not None:
        texture = buf.add_texture(doc, mesh.texture)
        material["pbrMetallicRoughness"] = {"baseColorTexture": {"index": texture}, "metallicFactor": 0.0}
    targets = []
    for frame in cloth.frames:
        f = np.asarray(frame, dtype=np.float64)
        targets.append(
            {
                "POSITION": buf.add(f - base, "VEC3", FLOAT, target=ARRAY_BUFFER, bounds=True),
                "NORMAL": buf.add(vertex_normals(f, mesh.faces) - base_n, "VEC3", FLOAT, target=ARRAY_BUFFER),
            }
        )
    indices = buf.add(mesh.faces.reshape(-1), "SCALAR", UINT, target=ELEMENT_ARRAY_BUFFER)
    primitive = {"attributes": attributes, "indices": indices, "material": len(materials), "targets": targets}
    meshes.append({"name": mesh.name or "cloth", "primitives": [primitive], "weights": [0.0] * len(targets)})
    materials.append(material)


def write_animated_glb(
    body,  # noqa: ANN001
    animation: BodyAnimation,
    path: str | os.PathLike[str],
    cloth: MorphMesh | None = None,
) -> Path:
    """Write `animated_glb` to `path` atomically."""
    data = animated_glb(body, animation, cloth)
    with atomic_path(path) as tmp:
        tmp.write_bytes(data)
    return Path(path)
