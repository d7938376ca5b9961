"""The rig of a body: rest joint positions on the kitsuke joint set and skin weights."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..skeleton import JOINTS, joint_index
from .skinning import forward_kinematics, global_rotations, rotations_from_positions, skin


@dataclass
class Rig:
    """Skeleton and skin weights of a body.

    joints : (J, 3) float64, rest positions of kitsuke.skeleton.JOINTS, metres, body frame.
    weights : (V, J) float64, skin weight of each vertex per joint; rows sum to 1. Joint j's weight moves a vertex
        with the bone that starts at j (the knee's weight is the shin).
    """

    joints: np.ndarray
    weights: np.ndarray

    def __post_init__(self) -> None:
        self.joints = np.asarray(self.joints, dtype=np.float64).reshape(len(JOINTS), 3)
        self.weights = np.asarray(self.weights, dtype=np.float64)
        if self.weights.ndim != 2 or self.weights.shape[1] != len(JOINTS):
            raise ValueError(f"weights must be (V, {len(JOINTS)}), got {self.weights.shape}")
        if not np.allclose(self.weights.sum(axis=1), 1.0, atol=1e-6):
            raise ValueError("skin weight rows must sum to 1")

    def joint(self, name: str) -> np.ndarray:
        """(3,) rest position of a named joint."""
        return self.joints[joint_index(name)]

    def weight_of(self, names: Sequence[str]) -> np.ndarray:
        """(V,) float64: each vertex's summed skin weight of the bones starting at the joints `names` (e.g.
        ("pelvis", "spine", "chest"): how much the torso moves it)."""
        return self.weights[:, [joint_index(n) for n in names]].sum(axis=1)


RotationLike = Any  # (3, 3) matrix, (3,) rotation vector in radians, (4,) quaternion w x y z, or scipy Rotation


def as_matrix(r: RotationLike) -> np.ndarray:
    """(3, 3) rotation matrix from a matrix, a rotation vector (radians), a wxyz quaternion or a scipy Rotation."""
    from scipy.spatial.transform import Rotation  # here: 0.15-0.3 s to import, and most commands never pose

    if isinstance(r, Rotation):
        return r.as_matrix()
    a = np.asarray(r, dtype=np.float64)
    if a.shape == (3, 3):
        return a
    if a.shape == (3,):
        return Rotation.from_rotvec(a).as_matrix()
    if a.shape == (4,):
        return Rotation.from_quat(a, scalar_first=True).as_matrix()
    raise ValueError(f"a rotation is a (3, 3) matrix, a (3,) rotation vector or a (4,) wxyz quaternion; got {a.shape}")


@dataclass
class PosedBody:
    """A body in a pose.

    vertices : (V, 3) float64, metres. joints : (J, 3) float64 posed joint positions.
    rotations : (J, 3, 3) float64 world rotation of each joint's bone relative to the rest pose.
    """

    vertices: np.ndarray
    joints: np.ndarray
    rotations: np.ndarray


def pose_rig(
    rig: Rig,
    vertices: np.ndarray,
    *,
    rotations: Mapping[str, RotationLike] | None = None,
    positions: Mapping[str, Any] | np.ndarray | None = None,
    root: np.ndarray | None = None,
) -> PosedBody:
    """Pose rest `vertices` (V, 3) by linear blend skinning; see `Body.pose` for the arguments."""
    if rotations is not None and positions is not None:
        raise ValueError("give rotations or positions, not both")
    if positions is not None:
        targets = np.full((len(JOINTS), 3), np.nan)
        if isinstance(positions, Mapping):
            for name, p in positions.items():
                targets[joint_index(name)] = p
        else:
            targets = np.asarray(positions, dtype=np.float64).reshape(len(JOINTS), 3)
        world = rotations_from_positions(rig.joints, targets)
        if root is None:
            root = targets[0] if np.isfinite(targets[0]).all() else rig.joints[0]
    else:
        local = np.tile(np.eye(3), (len(JOINTS), 1, 1))
        for name, r in (rotations or {}).items():
            local[joint_index(name)] = as_matrix(r)
        world = global_rotations(local)
    root = rig.joints[0] if root is None else np.asarray(root, dtype=np.float64)
    joints = forward_kinematics(rig.joints, world, root)
    return PosedBody(skin(vertices, rig.weights, rig.joints, world, joints), joints, world)
