"""glTF 2.0 binary (GLB) writing: the buffer of accessors, textures, the container, and static scenes of meshes.

    from kitsuke.geometry.gltf import static_glb
    data = static_glb([body_mesh, garment_mesh])     # bytes of a .glb: one node and mesh per TriMesh

Written here rather than through trimesh: importing trimesh (and the parts of scipy it pulls in) took 0.4-0.5 s of
every command that writes a GLB, and its exporter writes no skins or animations (`kitsuke.body.gltf_animation`
builds on the same pieces). Positions in metres; texture coordinates flipped to glTF's top-left origin.
"""

from __future__ import annotations

import io
import json
import struct

import numpy as np

from .mesh import TriMesh

FLOAT, USHORT, UINT = 5126, 5123, 5125
ARRAY_BUFFER, ELEMENT_ARRAY_BUFFER = 34962, 34963
REPEAT, LINEAR_MIPMAP_LINEAR, LINEAR = 10497, 9987, 9729


class GltfBuffer:
    """The GLB's binary chunk and its buffer views and accessors, built up one array at a time."""

    def __init__(self) -> None:
        self.data = bytearray()
        self.views: list[dict] = []
        self.accessors: list[dict] = []

    def _view(self, raw: bytes, target: int | None = None) -> int:
        while len(self.data) % 4:
            self.data.append(0)
        view = {"buffer": 0, "byteOffset": len(self.data), "byteLength": len(raw)}
        if target is not None:
            view["target"] = target
        self.data += raw
        self.views.append(view)
        return len(self.views) - 1

    def add(self, array: np.ndarray, kind: str, component: int, *, target: int | None = None, bounds: bool = False):
        """Append `array` (count, ...) as an accessor of `kind` ("VEC3", "MAT4", ...); returns its index."""
        dtype = {FLOAT: "<f4", USHORT: "<u2", UINT: "<u4"}[component]
        raw = np.ascontiguousarray(array, dtype=dtype)
        view = self._view(raw.tobytes(), target)
        acc = {"bufferView": view, "componentType": component, "count": len(raw), "type": kind}
        if bounds:
            flat = raw.reshape(len(raw), -1)
            acc["min"] = [float(x) for x in flat.min(axis=0)]
            acc["max"] = [float(x) for x in flat.max(axis=0)]
        self.accessors.append(acc)
        return len(self.accessors) - 1

    def add_texture(self, doc: dict, image: np.ndarray) -> int:
        """Append `image` (H, W, 3 or 4) uint8 as a PNG with a repeating, mipmapped sampler; returns the texture's
        index in `doc["textures"]` (the lists are created as needed)."""
        from PIL import Image

        png = io.BytesIO()
        Image.fromarray(np.asarray(image, dtype=np.uint8)).save(png, format="PNG")
        view = self._view(png.getvalue())
        doc.setdefault("images", []).append({"bufferView": view, "mimeType": "image/png"})
        doc.setdefault("samplers", []).append(
            {"magFilter": LINEAR, "minFilter": LINEAR_MIPMAP_LINEAR, "wrapS": REPEAT, "wrapT": REPEAT}
        )
        doc.setdefault("textures", []).append({"source": len(doc["images"]) - 1, "sampler": len(doc["samplers"]) - 1})
        return len(doc["textures"]) - 1

    def add_uv(self, uv: np.ndarray) -> int:
        """Texture coordinates (V, 2), origin bottom-left as in OBJ, as glTF's (origin top-left)."""
        return self.add(np.column_stack([uv[:, 0], 1.0 - uv[:, 1]]), "VEC2", FLOAT, target=ARRAY_BUFFER)


def vertex_normals(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """(V, 3) unit normals: the area-weighted sum of the faces' normals round each vertex."""
    n = np.cross(vertices[faces[:, 1]] - vertices[faces[:, 0]], vertices[faces[:, 2]] - vertices[faces[:, 0]])
    out = np.zeros_like(vertices)
    for k in range(3):
        np.add.at(out, faces[:, k], n)
    return out / np.maximum(np.linalg.norm(out, axis=1, keepdims=True), 1e-12)


def glb_bytes(doc: dict, binary: bytes) -> bytes:
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


def static_glb(meshes: list[TriMesh]) -> bytes:
    """The GLB bytes of a scene with one node and mesh per TriMesh, named after it: positions, normals, texture
    coordinates where it has them, and a double-sided material (its texture where it has one, else light grey)."""
    buf = GltfBuffer()
    doc: dict = {}
    nodes, out_meshes, materials = [], [], []
    for m in meshes:
        attributes = {
            "POSITION": buf.add(m.vertices, "VEC3", FLOAT, target=ARRAY_BUFFER, bounds=True),
            "NORMAL": buf.add(vertex_normals(m.vertices, m.faces), "VEC3", FLOAT, target=ARRAY_BUFFER),
        }
        pbr: dict = {"baseColorFactor": [0.8, 0.8, 0.8, 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.9}
        if m.uv is not None:
            attributes["TEXCOORD_0"] = buf.add_uv(m.uv)
            if m.texture is not None:
                pbr = {"baseColorTexture": {"index": buf.add_texture(doc, m.texture)}} | pbr
                pbr["baseColorFactor"] = [1.0, 1.0, 1.0, 1.0]
        indices = buf.add(m.faces.reshape(-1), "SCALAR", UINT, target=ELEMENT_ARRAY_BUFFER)
        materials.append({"name": m.name, "pbrMetallicRoughness": pbr, "doubleSided": True})
        primitive = {"attributes": attributes, "indices": indices, "material": len(materials) - 1}
        out_meshes.append({"name": m.name, "primitives": [primitive]})
        nodes.append({"name": m.name, "mesh": len(out_meshes) - 1})
    doc |= {
        "asset": {"version": "2.0", "generator": "kitsuke"},
        "scene": 0,
        "scenes": [{"nodes": list(range(len(nodes)))}],
        "nodes": nodes,
        "meshes": out_meshes,
        "materials": materials,
        "buffers": [{"byteLength": len(buf.data)}],
        "bufferViews": buf.views,
        "accessors": buf.accessors,
    }
    return glb_bytes(doc, bytes(buf.data))
