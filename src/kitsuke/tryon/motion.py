"""A body animation made ready for a garment dressed in the rest pose: the clip moved and turned to start where
the garment was dressed, and a lead-in that holds the rest pose, then blends into the clip's first frame.

A cloth simulation starts from a dressed garment, which lies on the body's rest pose. Jumping to the clip's
first frame would move the body through the cloth in one step (a BVH performer may start two metres away, facing
anywhere), so the lead-in walks there: `hold_s` at rest (the cloth settles under gravity), then `blend_s` in which
every joint's rotation slerps from the identity to the first frame's, and the root moves along.
"""

from __future__ import annotations

import numpy as np

from ..body.animate import BodyAnimation
from ..body.skinning import forward_kinematics
from ..errors import InputError
from ..skeleton import INDEX


def _yaw(rotation: np.ndarray) -> float:
    """Angle about +Y (radians) by which `rotation` (3, 3) turns the body's forward (+Z), in the floor plane."""
    f = rotation @ np.array([0.0, 0.0, 1.0])
    return float(np.arctan2(f[0], f[2]))


def _about_y(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def placed_at_rest(animation: BodyAnimation, rest_joints: np.ndarray) -> BodyAnimation:
    """The clip moved on the floor and turned about the vertical so that its first posed frame's pelvis stands
    over the rest pelvis and faces the rest pose's way (+Z). Heights are kept (the feet stay on the floor).
    rest_joints : (J, 3) metres."""
    first = int(np.flatnonzero(animation.valid)[0]) if animation.valid.any() else 0
    turn = _about_y(-_yaw(animation.rotations[first, INDEX["pelvis"]]))
    pelvis = animation.joints[first, INDEX["pelvis"]]
    joints = (animation.joints - pelvis) @ turn.T + pelvis
    shift = rest_joints[INDEX["pelvis"]] - pelvis
    shift[1] = 0.0
    rotations = np.einsum("ab,njbc->njac", turn, animation.rotations)
    return BodyAnimation(
        animation.times.copy(), animation.fps, rotations, joints + shift, animation.valid.copy(), animation.weights
    )


def _slerp_from_identity(rotations: np.ndarray, t: float) -> np.ndarray:
    """(J, 3, 3) each rotation of (J, 3, 3) taken a fraction t in [0, 1] of its way from the identity."""
    from scipy.spatial.transform import Rotation

    return Rotation.from_rotvec(Rotation.from_matrix(rotations).as_rotvec() * t).as_matrix()


def check_lead_in(hold_s: float, blend_s: float) -> None:
    """InputError unless both lead-in times are finite seconds >= 0."""
    if not (np.isfinite(hold_s) and hold_s >= 0 and np.isfinite(blend_s) and blend_s >= 0):
        raise InputError(f"the lead-in needs hold and blend times >= 0 s, got {hold_s} and {blend_s}")


def with_lead_in(
    animation: BodyAnimation, rest_joints: np.ndarray, *, hold_s: float = 0.2, blend_s: float = 0.5
) -> tuple[BodyAnimation, int]:
    """`animation` placed at the rest pose (`placed_at_rest`) with a lead-in before it: the rest pose held for
    `hold_s` seconds, then a smooth blend of `blend_s` seconds into its first frame (rotations slerped from the
    identity, the root along a straight line, eased in and out). Returns the longer animation and how many
    lead-in frames it starts with; frame times go on at the clip's rate, the clip keeps its own times shifted.
    rest_joints : (J, 3) the body's rest joints, metres."""
    check_lead_in(hold_s, blend_s)
    clip = placed_at_rest(animation, rest_joints)
    dt = 1.0 / clip.fps
    n_hold, n_blend = int(round(hold_s / dt)), int(round(blend_s / dt))
    n_lead = n_hold + n_blend
    first = int(np.flatnonzero(clip.valid)[0]) if clip.valid.any() else 0
    rot0, root0 = clip.rotations[first], clip.joints[first, INDEX["pelvis"]]
    identity = np.tile(np.eye(3), (len(rest_joints), 1, 1))
    rotations = np.empty((n_lead,) + clip.rotations.shape[1:])
    joints = np.empty((n_lead,) + clip.joints.shape[1:])
    for k in range(n_lead):
        t = 0.0 if k < n_hold else (k - n_hold + 1) / n_blend
        t = t * t * (3.0 - 2.0 * t)  # eased in and out: the limbs start and arrive without a jolt
        rotations[k] = identity if t == 0.0 else _slerp_from_identity(rot0, t)
        root = (1.0 - t) * rest_joints[INDEX["pelvis"]] + t * root0
        joints[k] = forward_kinematics(rest_joints, rotations[k], root)
    t0 = clip.times[0] - n_lead * dt
    return (
        BodyAnimation(
            np.concatenate([t0 + dt * np.arange(n_lead), clip.times]),
            clip.fps,
            np.concatenate([rotations, clip.rotations]),
            np.concatenate([joints, clip.joints]),
            np.concatenate([np.ones(n_lead, dtype=bool), clip.valid]),
            clip.weights,
        ),
        n_lead,
    )
