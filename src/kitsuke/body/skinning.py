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


def _rotation_between(a: np.ndarray, b: np.ndarray) -> np.ndarray:
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


def rotations_from_positions(rest_joints: np.ndarray, targets: np.ndarray) -> np.ndarray:
    """World rotations (J, 3, 3) that point every bone of the rest skeleton along the target skeleton's bones.

    rest_joints, targets : (J, 3) metres (NaN rows in targets = joint unknown: it keeps its parent's rotation).
    A joint with one child turns by the smallest rotation from its parent's frame (no invented twist); a joint with
    several children (pelvis, chest, ankle) takes the best-fitting rotation of all its child bones (Kabsch).
    Bone lengths are the body's own; only directions come from the targets.
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
            rot[j] = _rotation_between(src[0], dst[0]) @ base
        else:
            src_n = src / np.linalg.norm(src, axis=1, keepdims=True)
            dst_n = dst / np.linalg.norm(dst, axis=1, keepdims=True)
            rot[j] = _kabsch(src_n, dst_n) @ base
    return rot
