"""Body: a person's skin mesh in kitsuke's frame, with an optional rig (skeleton + skin weights) and capsules."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import InputError
from ..geometry import Conversion, MeshCheck, TriMesh, clean_mesh, plan_conversion, read_mesh
from ..geometry.units import Axis, Units
from .capsules import Capsule, capsule_segments, fit_capsules
from .rig import PosedBody, Rig, RotationLike, pose_rig


@dataclass
class Body:
    """A body in metres, Y up, facing +Z.

    mesh : the skin (TriMesh; vertices (V, 3) float64 metres).
    rig : skeleton and skin weights, or None for an unrigged body (it can be measured and dressed, not posed).
    capsules : capsules along limbs, neck and torso (empty without a rig).
    conversion : what was done to the file's units and axes. check : what validation found and cleaned.
    source : where it came from (a path, or "default").
    """

    mesh: TriMesh
    rig: Rig | None = None
    capsules: list[Capsule] = field(default_factory=list)
    conversion: Conversion = field(default_factory=Conversion)
    check: MeshCheck = field(default_factory=MeshCheck)
    source: str = ""

    @property
    def height_m(self) -> float:
        return float(np.ptp(self.mesh.vertices[:, 1]))

    @property
    def rigged(self) -> bool:
        return self.rig is not None

    def pose(
        self,
        *,
        rotations: Mapping[str, RotationLike] | None = None,
        positions: Mapping[str, Any] | np.ndarray | None = None,
        root: np.ndarray | None = None,
    ) -> PosedBody:
        """Pose the body by linear blend skinning.

        rotations : {joint: rotation} local to the parent, in rest-pose world axes — a (3, 3) matrix, a (3,) rotation
            vector in radians or a (4,) wxyz quaternion. Unnamed joints keep the rest pose.
            Example: bend the left knee 90 degrees: `{"l_knee": [np.pi / 2, 0, 0]}` (about +X: the shin swings back).
        positions : target joint positions, {joint: (3,)} or (J, 3) metres (NaN = unknown). Each bone is turned to
            point at its target; bone lengths stay the body's own.
        root : (3,) posed pelvis position, metres (default: the target pelvis, else the rest pelvis).
        Returns a PosedBody (vertices, joints, rotations).
        """
        if self.rig is None:
            raise InputError("this body has no rig, so it cannot be posed", self.source or None)
        return pose_rig(self.rig, self.mesh.vertices, rotations=rotations, positions=positions, root=root)

    def posed_mesh(self, posed: PosedBody) -> TriMesh:
        return TriMesh(posed.vertices, self.mesh.faces, self.mesh.uv, self.mesh.name, self.mesh.texture)

    def capsule_segments(self, posed: PosedBody | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Capsule endpoints (n, 2, 3) and end radii (n, 2), metres, in the rest pose or in `posed`."""
        if self.rig is None:
            return np.zeros((0, 2, 3)), np.zeros((0, 2))
        if posed is None:
            return capsule_segments(self.capsules, self.rig.joints)
        return capsule_segments(self.capsules, posed.joints, posed.rotations)

    def info(self) -> dict:
        """A JSON-ready summary (what `kitsuke body info` prints)."""
        lo, hi = self.mesh.bounds
        return {
            "source": self.source,
            "vertices": self.mesh.n_vertices,
            "faces": self.mesh.n_faces,
            "height_m": round(self.height_m, 4),
            "bounds_m": [np.round(lo, 4).tolist(), np.round(hi, 4).tolist()],
            "conversion": {
                "units": self.conversion.units,
                "scale_to_m": self.conversion.scale,
                "up": self.conversion.up,
                "facing": self.conversion.facing,
                "applied": not self.conversion.is_identity,
                "notes": self.conversion.notes,
            },
            "watertight": self.check.watertight,
            "holes": self.check.holes,
            "non_manifold_edges": self.check.non_manifold_edges,
            "cleaned": {
                "degenerate_faces": self.check.removed_degenerate_faces,
                "duplicate_faces": self.check.removed_duplicate_faces,
                "unreferenced_vertices": self.check.removed_unreferenced_vertices,
                "triangulated_polygons": self.check.triangulated_polygons,
            },
            "rigged": self.rigged,
            "joints": None if self.rig is None else len(self.rig.joints),
            "capsules": [c.name for c in self.capsules],
        }


def load_body(
    path: str | Path,
    *,
    units: Units = "auto",
    up: Axis = "auto",
    facing: Axis = "auto",
    group: str | None = None,
) -> Body:
    """Load a body from OBJ, GLB/glTF or PLY: validated, cleaned and converted to metres, Y up, facing +Z.

    units, up, facing : "auto" detects them (see kitsuke.geometry.units); give them to override.
    group : keep one OBJ group (e.g. "body" for a MakeHuman base mesh).
    Raises InputError naming the file for anything unusable. A loaded file has no rig (use `default_body()` for a
    rigged one).
    """
    mesh, n_poly = read_mesh(path, group=group)
    mesh, check = clean_mesh(mesh, source=str(path))
    check.triangulated_polygons = n_poly
    conv = plan_conversion(mesh.vertices, units=units, up=up, facing=facing, source=str(path))
    mesh.vertices = conv.apply(mesh.vertices)
    height = float(np.ptp(mesh.vertices[:, 1]))
    if not 0.3 <= height <= 3.0:
        raise InputError(f"body is {height:.2f} m tall after conversion; pass --units to say its units", path)
    return Body(mesh=mesh, conversion=conv, check=check, source=str(path))


def default_body() -> Body:
    """The packaged default body: MakeHuman's CC0 base mesh, 1.67 m, A-pose, feet on y = 0, rigged."""
    ref = resources.files("kitsuke.assets") / "body" / "default_body.npz"
    with resources.as_file(ref) as p, np.load(p) as z:
        mesh = TriMesh(z["vertices"], z["faces"].astype(np.int64), z["uv"], name="default_body")
        weights = z["weights"].astype(np.float64)
        rig = Rig(z["joints"], weights / weights.sum(axis=1, keepdims=True))
    check = MeshCheck(watertight=True)
    body = Body(mesh=mesh, rig=rig, check=check, source="default")
    body.capsules = fit_capsules(mesh.vertices, rig)
    return body
