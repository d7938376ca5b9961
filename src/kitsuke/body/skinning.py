"""Forward kinematics and linear blend skinning on the kitsuke joint set (arrays only, no I/O).

Frames: every joint's rest frame is the world frame (the rest pose defines zero rotation), so a joint rotation is
expressed in world axes of the rest pose. Rotations are (3, 3) float64 matrices.
"""

from __future__ import annotations

import numpy as np

from ..skeleton import CHILDREN, INDEX, JOINTS, PARENT_INDEX

N_JOINTS = len(JOINTS)


def global_rotations(local: np.ndarray) -> np.ndarray:
    """Compose local joint rotations down the tree.

    local : (J, 3, 3) rotation of each joint relative to its parent (rest-pose axes).
    Returns (J, 3, 3) world rotations, G_j = G_parent(j) @ local_j.
    """
    out = np.empty_like(local)
    for j, p in enumerate(PARENT_INDEX):  # J = 23: the tree walk is cheap; the per-vertex work is vectorised below
        out[j] = local[j] if p < 0 else out[p] @ local[j]
    return out


def forward_kinematics(rest_joints: np.ndarray, rotations: np.ndarray, root: np.ndarray) -> np.ndarray:
    """Posed joint positions (J, 3), metres.

    rest_joints : (J, 3) rest positions. rotations : (J, 3, 3) world rotations. root : (3,) posed pelvis position.
    A child sits at its parent plus the parent's rotation applied to the rest bone, so bone lengths never change.
    """
    posed = np.empty_like(rest_joints)
    for j, p in enumerate(PARENT_INDEX):
        posed[j] = root if p < 0 else posed[p] + rotations[p] @ (rest_joints[j] - rest_joints[p])
    return posed


def skin(
    vertices: np.ndarray,
    weights: np.ndarray,
    rest_joints: np.ndarray,
    rotations: np.ndarray,
    posed_joints: np.ndarray,
) -> np.ndarray:
    """Linear blend skinning: v' = sum_j w_j (R_j (v - J_j) + P_j).

    vertices : (V, 3) rest positions. weights : (V, J), rows sum to 1. rest_joints, posed_joints : (J, 3).
    rotations : (J, 3, 3) world rotations. Returns (V, 3) posed positions.
    """
    offsets = posed_joints - np.einsum("jab,jb->ja", rotations, rest_joints)  # (J, 3): P_j - R_j J_j
    blend_r = (weights @ rotations.reshape(N_JOINTS, 9)).reshape(-1, 3, 3)  # (V, 3, 3)
    return np.einsum("vab,vb->va", blend_r, vertices) + weights @ offsets


def rotation_between(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Smallest rotation taking direction a to direction b (both (3,), any length)."""
    a = a / np.linalg.norm(a)
    b = b / np.linalg.norm(b)
    v = np.cross(a, b)
    c = float(a @ b)
    s = float(np.linalg.norm(v))
    if s < 1e-12:
        if c > 0:
            return np.eye(3)
        # Opposite: turn half-way round any axis perpendicular to a.
        axis = np.cross(a, [1.0, 0.0, 0.0] if abs(a[0]) < 0.9 else [0.0, 1.0, 0.0])
        axis /= np.linalg.norm(axis)
        return 2.0 * np.outer(axis, axis) - np.eye(3)
    k = np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])
    return np.eye(3) + k + k @ k * ((1 - c) / s**2)


def _kabsch(src: np.ndarray, dst: np.ndarray) -> np.ndarray:
    """Rotation R minimising sum |R src_i - dst_i|^2 over direction sets (n, 3)."""
    u, _, vt = np.linalg.svd(dst.T @ src)
    d = np.sign(np.linalg.det(u @ vt)) or 1.0
    return u @ np.diag([1.0, 1.0, d]) @ vt


#: Limb roots whose twist the limb's bend decides: (middle joint, end joint, the way the end swings when the middle
#: joint bends, in the rest pose): knees bend back, elbows forward.
LIMBS: dict[str, tuple[str, str, tuple[float, float, float]]] = {
    "l_hip": ("l_knee", "l_ankle", (0.0, 0.0, -1.0)),
    "r_hip": ("r_knee", "r_ankle", (0.0, 0.0, -1.0)),
    "l_shoulder": ("l_elbow", "l_wrist", (0.0, 0.0, 1.0)),
    "r_shoulder": ("r_elbow", "r_wrist", (0.0, 0.0, 1.0)),
}
#: A limb bent less than the first angle keeps the twist of its parent's frame (a straight limb shows no hinge);
#: from the second, its hinge follows the bend; in between, a blend.
TWIST_FROM_BEND_DEG = (10.0, 30.0)


def _about(axis: np.ndarray, angle: float) -> np.ndarray:
    """Rotation by `angle` radians about the unit `axis` (Rodrigues)."""
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + np.sin(angle) * k + (1.0 - np.cos(angle)) * (k @ k)


def rest_hinge(rest_bone: np.ndarray, rest_next: np.ndarray, bend_dir: np.ndarray) -> np.ndarray:
    """(3,) unit hinge axis of a limb in the rest pose: its bend's normal where the rest limb is bent (the default
    body's elbows, 47°), else rest_bone × bend_dir (its nearly straight knees)."""
    natural = np.cross(rest_bone, bend_dir)
    normal = np.cross(rest_bone, rest_next)
    sin_bend = np.linalg.norm(normal) / max(np.linalg.norm(rest_bone) * np.linalg.norm(rest_next), 1e-12)
    if sin_bend >= np.sin(np.radians(TWIST_FROM_BEND_DEG[0])):
        h = normal if normal @ natural >= 0 else -normal
    else:
        h = natural
    return h / np.linalg.norm(h)


def limb_twist(swing: np.ndarray, hinge_rest: np.ndarray, bone: np.ndarray, next_bone: np.ndarray) -> np.ndarray:
    """The limb root's rotation `swing` (3, 3), turned about its bone so that the limb's hinge lies across its bend.

    hinge_rest : (3,) unit hinge axis in the rest pose (`rest_hinge`). bone, next_bone : (3,) the first and second
    bone of the target; its hinge is bone × next_bone. A straight limb keeps `swing` (its twist follows the parent:
    the hip line for a leg, the shoulder line for an arm). A limb bent the wrong way (a hyperextended knee, or noise)
    is turned less than a quarter turn, never flipped round.
    """
    b = bone / np.linalg.norm(bone)
    c = next_bone / max(np.linalg.norm(next_bone), 1e-12)
    normal = np.cross(b, c)
    sin_bend = float(np.linalg.norm(normal))
    lo, hi = np.sin(np.radians(TWIST_FROM_BEND_DEG))
    w = float(np.clip((sin_bend - lo) / (hi - lo), 0.0, 1.0))
    if w == 0.0:
        return swing
    h = swing @ hinge_rest
    h = h - (h @ b) * b
    target = normal / sin_bend
    phi = float(np.arctan2(b @ np.cross(h, target), h @ target))
    if abs(phi) > 0.5 * np.pi:  # bent against the hinge: the nearer of the two hinge directions
        phi -= np.copysign(np.pi, phi)
    return _about(b, w * phi) @ swing


#: The largest turn of a joint from its parent's frame that retargeting allows, degrees: what the joint can do
#: (a collar bone moves little, a trunk segment bends, a foot flexes). Noisy or collapsed poses (a side view where
#: MediaPipe puts both shoulders on one spot) then cannot turn a collar bone round and tear the skin.
JOINT_LIMITS_DEG: dict[str, float] = {
    "spine": 60.0,
    "chest": 60.0,
    "neck": 60.0,
    "head": 70.0,
    "l_clavicle": 35.0,
    "r_clavicle": 35.0,
    "l_ankle": 70.0,
    "r_ankle": 70.0,
}


def _clamped(local: np.ndarray, limit_deg: float) -> np.ndarray:
    """`local` (3, 3) if it turns at most `limit_deg`, else the same turn shortened to `limit_deg`."""
    angle = float(np.arccos(np.clip((np.trace(local) - 1.0) / 2.0, -1.0, 1.0)))
    limit = np.radians(limit_deg)
    if angle <= limit:
        return local
    axis = np.array([local[2, 1] - local[1, 2], local[0, 2] - local[2, 0], local[1, 0] - local[0, 1]])
    n = np.linalg.norm(axis)
    if n < 1e-9:  # a half turn: any perpendicular axis is as good; take the symmetric part's main direction
        w, v = np.linalg.eigh(local + local.T)
        axis = v[:, np.argmax(w)]
    else:
        axis = axis / n
    return _about(axis, limit)


def rotations_from_positions(rest_joints: np.ndarray, targets: np.ndarray) -> np.ndarray:
    """World rotations (J, 3, 3) that point every bone of the rest skeleton along the target skeleton's bones.

    rest_joints, targets : (J, 3) metres (NaN rows in targets = joint unknown: it keeps its parent's rotation).
    A joint with one child turns by the smallest rotation from its parent's frame; a joint with several children
    (pelvis, chest, ankle) takes the best-fitting rotation of all its child bones (Kabsch). A hip or shoulder is
    then twisted about its bone so that the knee's or elbow's hinge lies across the limb's bend (`limb_twist`):
    the shin and forearm then swing in their joint's plane instead of twisting the skin. A joint turns at most
    `JOINT_LIMITS_DEG` from its parent's frame. Bone lengths are the body's own; only directions come from the
    targets.
    """
    rot = np.tile(np.eye(3), (N_JOINTS, 1, 1))
    for j, name in enumerate(JOINTS):
        p = PARENT_INDEX[j]
        base = np.eye(3) if p < 0 else rot[p]
        kids = [INDEX[c] for c in CHILDREN[name]]
        if np.isnan(targets[j]).any():
            rot[j] = base
            continue
        kids = [k for k in kids if not np.isnan(targets[k]).any()]
        if not kids:
            rot[j] = base
            continue
        src = np.array([base @ (rest_joints[k] - rest_joints[j]) for k in kids])
        dst = np.array([targets[k] - targets[j] for k in kids])
        ok = (np.linalg.norm(src, axis=1) > 1e-9) & (np.linalg.norm(dst, axis=1) > 1e-9)
        src, dst = src[ok], dst[ok]
        if len(src) == 0:
            rot[j] = base
        elif len(src) == 1:
            rot[j] = rotation_between(src[0], dst[0]) @ base
            limb = LIMBS.get(name)
            if limb is not None:
                mid, end = INDEX[limb[0]], INDEX[limb[1]]
                if np.isfinite(targets[end]).all():
                    h = rest_hinge(
                        rest_joints[mid] - rest_joints[j], rest_joints[end] - rest_joints[mid], np.array(limb[2])
                    )
                    rot[j] = limb_twist(rot[j], h, dst[0], targets[end] - targets[mid])
        else:
            src_n = src / np.linalg.norm(src, axis=1, keepdims=True)
            dst_n = dst / np.linalg.norm(dst, axis=1, keepdims=True)
            rot[j] = _kabsch(src_n, dst_n) @ base
        limit = JOINT_LIMITS_DEG.get(name)
        if limit is not None:
            rot[j] = base @ _clamped(base.T @ rot[j], limit)
    return rot
