"""An animated, skinned GLB of a body (glTF 2.0, written here: trimesh writes no skins or animations).

One mesh skinned to the 23 joints of `kitsuke.skeleton` (four weights per vertex, the largest, renormalised: what
glTF viewers and three.js read), the joints as a node tree whose rest pose is the body's (every joint's rest
orientation is the world's, so a node's translation is its rest bone), and one animation: each joint's rotation
relative to its parent and the root's translation, per frame, linearly interpolated (quaternions slerped).
"""

from __future__ import annotations

import json
import os
import struct
from pathlib import Path

import numpy as np

from .._files import atomic_path
from ..skeleton import JOINTS, PARENT_INDEX
from .animate import BodyAnimation

_FLOAT, _USHORT, _UINT = 5126, 5123, 5125
_ARRAY, _ELEMENTS = 34962, 34963


class _Buffer:
    """The GLB's binary chunk and its accessors, built up one array at a time."""

    def __init__(self) -> None:
        self.data = bytearray()
        self.views: list[dict] = []
        self.accessors: list[dict] = []

    def add(self, array: np.ndarray, kind: str, component: int, *, target: int | None = None, bounds: bool = False):
        """Append `array` (count, ...) as an accessor of `kind` ("VEC3", "MAT4", ...); returns its index."""
        dtype = {_FLOAT: "<f4", _USHORT: "<u2", _UINT: "<u4"}[component]
        raw = np.ascontiguousarray(array, dtype=dtype)
        while len(self.data) % 4:
            self.data.append(0)
        view = {"buffer": 0, "byteOffset": len(self.data), "byteLength": raw.nbytes}
        if target is not None:
            view["target"] = target
        self.data += raw.tobytes()
        self.views.append(view)
        acc = {"bufferView": len(self.views) - 1, "componentType": component, "count": len(raw), "type": kind}
        if bounds:
            flat = raw.reshape(len(raw), -1)
            acc["min"] = [float(x) for x in flat.min(axis=0)]
            acc["max"] = [float(x) for x in flat.max(axis=0)]
        self.accessors.append(acc)
        return len(self.accessors) - 1


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


def animated_glb(body, animation: BodyAnimation) -> bytes:  # noqa: ANN001 - a rigged kitsuke.body.Body
    """The GLB bytes of `body` skinned and moved by `animation`."""
    mesh, rig = body.mesh, body.rig
    buf = _Buffer()
    normals = _vertex_normals(mesh.vertices, mesh.faces)
    joints4, weights4 = _top4(animation.weights)
    attributes = {
        "POSITION": buf.add(mesh.vertices, "VEC3", _FLOAT, target=_ARRAY, bounds=True),
        "NORMAL": buf.add(normals, "VEC3", _FLOAT, target=_ARRAY),
        "JOINTS_0": buf.add(joints4, "VEC4", _USHORT, target=_ARRAY),
        "WEIGHTS_0": buf.add(weights4, "VEC4", _FLOAT, target=_ARRAY),
    }
    if mesh.uv is not None:
        attributes["TEXCOORD_0"] = buf.add(
            np.column_stack([mesh.uv[:, 0], 1.0 - mesh.uv[:, 1]]), "VEC2", _FLOAT, target=_ARRAY
        )
    indices = buf.add(mesh.faces.reshape(-1), "SCALAR", _UINT, target=_ELEMENTS)
    # inverse bind matrices: the joints' rest frames are translations only (column-major 4x4)
    ibm = np.tile(np.eye(4), (len(JOINTS), 1, 1))
    ibm[:, :3, 3] = -rig.joints
    ibm_acc = buf.add(ibm.transpose(0, 2, 1).reshape(len(JOINTS), 16), "MAT4", _FLOAT)

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

    times = buf.add(animation.times - animation.times[0], "SCALAR", _FLOAT, bounds=True)
    local = animation.local_rotations
    samplers, channels = [], []
    for j in range(len(JOINTS)):
        out = buf.add(_quaternions(local[:, j]), "VEC4", _FLOAT)
        samplers.append({"input": times, "output": out, "interpolation": "LINEAR"})
        channels.append({"sampler": len(samplers) - 1, "target": {"node": first_joint + j, "path": "rotation"}})
    root = buf.add(animation.joints[:, 0], "VEC3", _FLOAT)
    samplers.append({"input": times, "output": root, "interpolation": "LINEAR"})
    channels.append({"sampler": len(samplers) - 1, "target": {"node": first_joint, "path": "translation"}})

    doc = {
        "asset": {"version": "2.0", "generator": "kitsuke"},
        "scene": 0,
        "scenes": [{"nodes": [0, first_joint]}],
        "nodes": nodes,
        "meshes": [{"name": "body", "primitives": [{"attributes": attributes, "indices": indices, "material": 0}]}],
        "materials": [
            {
                "name": "skin",
                "pbrMetallicRoughness": {"baseColorFactor": [0.85, 0.72, 0.62, 1.0], "metallicFactor": 0.0},
                "doubleSided": False,
            }
        ],
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
    return _glb(doc, bytes(buf.data))


def _vertex_normals(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    n = np.cross(vertices[faces[:, 1]] - vertices[faces[:, 0]], vertices[faces[:, 2]] - vertices[faces[:, 0]])
    out = np.zeros_like(vertices)
    for k in range(3):
        np.add.at(out, faces[:, k], n)
    return out / np.maximum(np.linalg.norm(out, axis=1, keepdims=True), 1e-12)


def _glb(doc: dict, binary: bytes) -> bytes:
    """A GLB container: header, JSON chunk (space-padded), BIN chunk (zero-padded)."""
    text = json.dumps(doc, separators=(",", ":")).encode()
    text += b" " * (-len(text) % 4)
    binary += b"\0" * (-len(binary) % 4)
    total = 12 + 8 + len(text) + 8 + len(binary)
    return (
        struct.pack("<4sII", b"glTF", 2, total)
        + struct.pack("<I4s", len(text), b"JSON")
        + text
        + struct.pack("<I4s", len(binary), b"BIN\0")
        + binary
    )


def write_animated_glb(body, animation: BodyAnimation, path: str | os.PathLike[str]) -> Path:  # noqa: ANN001
    """Write `animated_glb` to `path` atomically."""
    data = animated_glb(body, animation)
    with atomic_path(path) as tmp:
        tmp.write_bytes(data)
    return Path(path)
