"""Names for places on a standing body ("under the right arm", "at the back of the waist", "on the left thigh"), so
that a message can say where on the body something happened instead of giving coordinates alone.

The torso's and legs' parts are told apart by shares of the body's height, set between the landmarks of the
usual anthropometric proportions (Drillis and Contini: chin 0.87, shoulder 0.82, chest 0.72, hip joint 0.53,
knee 0.29, ankle 0.04 of the height): the neck from 0.87, the shoulders from 0.79, the chest from 0.66, the waist
from 0.57, the hips down to the crotch (measured where the legs part, `kitsuke.body.legs`; 0.47 where they do not),
the knee from 0.24 to 0.33. The arms are found from the mesh (`kitsuke.body.arms`), and the neck then starts above
the armpits; a body whose arms are not found has its arms' places named by height.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..geometry import TriMesh
from ..geometry.section import section_parts
from .arms import ArmAxis, arm_axes
from .legs import leg_gap

#: (share of the body's height above the floor, the torso part from there up), highest first.
TORSO_PARTS = ((0.87, "neck"), (0.79, "shoulders"), (0.66, "chest"), (0.57, "waist"), (0.0, "hips"))
#: Where the arms are found, the neck starts this far above the armpits, metres (GarmentCode's mean_all, 1.72 m
#: tall, carries its neck lower than 0.87 of its height; MakeHuman's default body agrees with both).
NECK_ABOVE_ARMPIT_M = 0.16
#: (share of the height, the leg part from there up), highest first; below the crotch.
LEG_PARTS = ((0.33, "thigh"), (0.24, "knee"), (0.06, "shin"), (0.0, "ankle"))
#: A point this many arm radii (plus ARM_MARGIN_M) from an arm's axis, and along it, is on that arm.
ARM_REACH = 2.5
ARM_MARGIN_M = 0.04
#: Along the arm from where it leaves the torso, metres: nearer than this is the armpit (below the axis) or the
#: shoulder (above it).
ARMPIT_M = 0.04


@dataclass(frozen=True)
class BodyRegions:
    """What naming places needs of a standing body (metres, Y up, facing +Z, the person's left at +X).

    floor_y, height_m : the soles' height and the body's height. centre : (2,) x, z of the body's vertical axis
    (its bounding box's middle). crotch_y : where the legs part (None: not found; LEG_PARTS then start at 0.47 of the
    height). arms : `arm_axes` of the body ("left", "right"; either may be missing). mesh : the body, whose
    cross-section at a point's height says where the torso's front and back are there (None: the centre's).
    """

    floor_y: float
    height_m: float
    centre: np.ndarray
    crotch_y: float | None
    arms: dict[str, ArmAxis]
    mesh: TriMesh | None = None

    @classmethod
    def of(cls, mesh: TriMesh) -> BodyRegions:
        """Measure `mesh` (about 0.1 s for a 24k-vertex body: the arms' cross-sections)."""
        v = mesh.vertices
        lo, hi = v.min(axis=0), v.max(axis=0)
        gap = leg_gap(mesh)
        centre = 0.5 * (lo + hi)[[0, 2]]
        return cls(float(lo[1]), float(hi[1] - lo[1]), centre, gap and gap.crotch_y, arm_axes(mesh), mesh)

    def name(self, point: np.ndarray) -> str:
        """Where `point` (3,) metres lies, e.g. "under the right arm", "at the front of the waist", "on the left
        thigh"; a point beside the body is named after the part it is beside (below the soles: the ankle; above the
        head: the neck). Raises InputError for anything but 3 finite numbers."""
        p = np.asarray(point, dtype=np.float64)
        if p.shape != (3,) or not np.isfinite(p).all():
            raise InputError(f"a point on the body must be 3 finite numbers, got {point!r}")
        arm = self._arm(p)
        if arm:
            return arm
        share = min(max((p[1] - self.floor_y) / self.height_m, 0.0), 1.0)
        side = "left" if p[0] > self.centre[0] else "right"
        crotch = 0.47 if self.crotch_y is None else (self.crotch_y - self.floor_y) / self.height_m
        if share < crotch:
            part = next(name for low, name in LEG_PARTS if share >= low)
            return f"{'at' if part in ('knee', 'ankle') else 'on'} the {side} {part}"
        part = next(name for low, name in TORSO_PARTS if share >= low)
        if self.arms and p[1] > min(a.start[1] for a in self.arms.values()) + NECK_ABOVE_ARMPIT_M:
            part = "neck"
        x, z = p[[0, 2]] - self._middle(float(p[1]))
        turn = np.degrees(np.arctan2(x, z))  # 0: straight ahead, ±180: behind
        if abs(turn) <= 45:
            return f"at the front of the {part}"
        if abs(turn) >= 135:
            return f"at the back of the {part}"
        return f"at the {side} side of the {part}"

    def _middle(self, y: float) -> np.ndarray:
        """(2,) x, z: the middle of the torso's cross-section at height `y` (the part nearest the vertical axis), or
        the centre where the cut misses the body."""
        parts = [] if self.mesh is None else section_parts(self.mesh.vertices, self.mesh.faces, y)
        if not parts:
            return self.centre
        torso = min(parts, key=lambda q: abs(q[:, 0].mean() - self.centre[0]))
        return 0.5 * (torso.min(axis=0) + torso.max(axis=0))[[0, 2]]

    def _arm(self, p: np.ndarray) -> str:
        """The arm place of `p` ("under the left arm", "at the right shoulder", "on the left upper arm", "on the
        right forearm"), or "" where it is not on an arm."""
        for side, arm in self.arms.items():
            rel = p - arm.start
            along = float(rel @ arm.direction)
            across = rel - along * arm.direction
            reach = ARM_REACH * arm.radius_m + ARM_MARGIN_M
            if not -0.03 < along < arm.hand_m + 0.05 or np.linalg.norm(across) > reach:
                continue
            if along < ARMPIT_M:
                up = np.array([0.0, 1.0, 0.0]) - arm.direction[1] * arm.direction
                return f"under the {side} arm" if across @ up < 0 else f"at the {side} shoulder"
            elbow = min(arm.length_m, 0.5 * arm.hand_m)  # where the straight upper arm ends, or halfway
            return f"on the {side} {'upper arm' if along < elbow else 'forearm'}"
        return ""
