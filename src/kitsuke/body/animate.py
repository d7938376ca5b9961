"""A rigged body posed over a pose sequence (retargeting joint positions onto the body's own skeleton), and how
well its skin holds up (no flipped or pinched triangles at the elbows, knees and hips).

Retargeting, per frame (`rotations_from_positions`): every bone turns to point along the observed one, the body
keeping its own bone lengths; a hip or shoulder twists so that the knee or elbow bends about its own hinge
(`limb_twist`), and a straight limb keeps the twist of the pelvis or chest (their rotation comes from all their
child bones: the hip line, the shoulder line). The root follows the observed pelvis; the whole clip is then moved
up or down once so that the feet stand on y = 0 (MediaPipe's poses are hip-centred, a BVH performer's legs are not
the body's). Frames without a pose hold the last posed frame (the rest pose before the first).

Skinning: linear blend skinning with the rig's weights diffused over the mesh (`animation_weights`: 100 steps of
averaging each vertex's weights with its neighbours'). The MakeHuman weights change sharply across the armpits,
knees and groin; LBS then pinches and stretches small edges there (walking: knee edges shrunk to 7 % with 29 faces
turned inside out, shoulder edges stretched 8-fold). Diffused, the same walk keeps knee edges above 19 % with none
turned (see BENCHMARKS.md); the rest pose is unchanged (every rotation is the identity there).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..skeleton import INDEX, JOINTS, PARENT_INDEX
from .skinning import forward_kinematics, rotations_from_positions, skin

#: Steps of weight diffusion for animation (see the module docstring; 10, 30, 100, 200, 400 were measured).
WEIGHT_DIFFUSION_STEPS = 100

_FEET = [INDEX[j] for j in ("l_ankle", "l_heel", "l_toe", "r_ankle", "r_heel", "r_toe")]


@dataclass
class BodyAnimation:
    """A body's skeleton over time.

    times : (n,) float64 seconds. fps : frames per second.
    rotations : (n, J, 3, 3) float64 world rotations of each joint (the rest pose is the identity).
    joints : (n, J, 3) float64 posed joint positions, metres, Y up.
    valid : (n,) bool, frames posed from an observed pose (the others hold the previous one).
    weights : (V, J) float64 skin weights the animation is skinned with (`animation_weights`).
    """

    times: np.ndarray
    fps: float
    rotations: np.ndarray
    joints: np.ndarray
    valid: np.ndarray
    weights: np.ndarray

    @property
    def n_frames(self) -> int:
        return len(self.times)

    @property
    def local_rotations(self) -> np.ndarray:
        """(n, J, 3, 3) each joint's rotation relative to its parent's (the root's: world)."""
        out = self.rotations.copy()
        for j, p in enumerate(PARENT_INDEX):
            if p >= 0:
                out[:, j] = np.einsum("nba,nbc->nac", self.rotations[:, p], self.rotations[:, j])
        return out


def animate(body, poses) -> BodyAnimation:  # noqa: ANN001 - Body and PoseSequence (no import cycle)
    """Pose `body` (rigged: `default_body()`) over `poses` (a `kitsuke.pose.PoseSequence`).

    InputError when the body has no rig or the sequence has no frame with a pose.
    """
    if body.rig is None:
        raise InputError("this body has no rig, so it cannot be animated (use the default body)", body.source or None)
    pos = np.asarray(poses.positions, dtype=np.float64)
    valid = np.asarray(poses.valid, dtype=bool).copy()
    if not valid.any():
        raise InputError("the poses have no frame with a person in it", poses.source.get("path"))
    rest = body.rig.joints
    n = len(pos)
    rotations = np.tile(np.eye(3), (n, len(JOINTS), 1, 1))
    joints = np.tile(rest, (n, 1, 1))
    last = None
    for f in range(n):
        if valid[f]:
            rot = rotations_from_positions(rest, pos[f])
            last = (rot, forward_kinematics(rest, rot, pos[f, 0]))
        if last is not None:
            rotations[f], joints[f] = last
    # feet on the ground: one vertical shift for the clip (per frame it would hide jumps and squats)
    lowest = joints[valid][:, _FEET, 1].min(axis=1)
    joints[:, :, 1] -= float(np.percentile(lowest, 5)) - float(rest[_FEET, 1].min())
    times = np.asarray(poses.times, dtype=np.float64)
    return BodyAnimation(times, float(poses.fps), rotations, joints, valid, animation_weights(body))


def animation_weights(body, steps: int = WEIGHT_DIFFUSION_STEPS) -> np.ndarray:  # noqa: ANN001
    """(V, J) the rig's skin weights diffused over the mesh: `steps` times, each vertex's weights become the mean of
    its own and its neighbours' average; then each vertex keeps its four largest (what glTF viewers and three.js
    skin with, so that the GLB plays exactly what the library computes), renormalised to sum to 1."""
    import scipy.sparse as sp

    f = body.mesh.faces
    n = len(body.mesh.vertices)
    rows = np.concatenate([f[:, 0], f[:, 1], f[:, 2], f[:, 1], f[:, 2], f[:, 0]])
    cols = np.concatenate([f[:, 1], f[:, 2], f[:, 0], f[:, 0], f[:, 1], f[:, 2]])
    adj = sp.csr_matrix((np.ones(len(rows)), (rows, cols)), shape=(n, n))
    adj.data[:] = 1.0  # an edge shared by two faces counts once
    step = 0.5 * sp.identity(n, format="csr") + 0.5 * sp.diags(1.0 / np.maximum(adj.sum(axis=1).A1, 1)) @ adj
    w = body.rig.weights
    for _ in range(steps):
        w = step @ w
    keep = np.argsort(-w, axis=1)[:, :4]
    out = np.zeros_like(w)
    np.put_along_axis(out, keep, np.take_along_axis(w, keep, axis=1), axis=1)
    return out / out.sum(axis=1, keepdims=True)


def posed_vertices(body, animation: BodyAnimation, frame: int) -> np.ndarray:  # noqa: ANN001
    """(V, 3) the body's skin at `frame` (linear blend skinning)."""
    rig = body.rig
    return skin(body.mesh.vertices, animation.weights, rig.joints, animation.rotations[frame], animation.joints[frame])


#: Where the skin bends, by the two bones that meet there (a vertex belongs when both move it by 10 % or more).
REGIONS: dict[str, tuple[tuple[str, str], ...]] = {
    "hips": (("pelvis", "l_hip"), ("pelvis", "r_hip")),
    "knees": (("l_hip", "l_knee"), ("r_hip", "r_knee")),
    "elbows": (("l_shoulder", "l_elbow"), ("r_shoulder", "r_elbow")),
    "shoulders": (("chest", "l_shoulder"), ("chest", "r_shoulder"), ("l_clavicle", "l_shoulder")),
}


def _region_faces(weights: np.ndarray, faces: np.ndarray, pairs) -> np.ndarray:  # noqa: ANN001
    inside = np.zeros(len(weights), dtype=bool)
    for a, b in pairs:
        inside |= (weights[:, INDEX[a]] >= 0.1) & (weights[:, INDEX[b]] >= 0.1)
    return inside[faces].all(axis=1)


def skinning_quality(body, animation: BodyAnimation, frames: np.ndarray | None = None) -> dict[str, dict]:  # noqa: ANN001
    """How the skin holds up over `frames` (default all), per region (`REGIONS`) and over the whole body: the
    shortest and longest edge against its rest length (a pinch shrinks edges, a candy-wrapper twist stretches
    them), and the most faces turned inside out in one frame (a face whose normal points against its rest normal
    carried by the bone that moves it most)."""
    mesh = body.mesh
    faces = mesh.faces
    rest_v = mesh.vertices
    rest_n = np.cross(rest_v[faces[:, 1]] - rest_v[faces[:, 0]], rest_v[faces[:, 2]] - rest_v[faces[:, 0]])
    owner = np.argmax(body.rig.weights[faces].sum(axis=1), axis=1)  # (F,) the joint that moves each face most
    sel = {name: _region_faces(body.rig.weights, faces, pairs) for name, pairs in REGIONS.items()}
    sel["all"] = np.ones(len(faces), dtype=bool)
    corner = [(0, 1), (1, 2), (2, 0)]
    rest_len = np.stack([np.linalg.norm(rest_v[faces[:, b]] - rest_v[faces[:, a]], axis=1) for a, b in corner], 1)
    out = {name: {"min_edge_ratio": np.inf, "max_edge_ratio": 0.0, "max_inverted_faces": 0} for name in sel}
    for f in range(animation.n_frames) if frames is None else frames:
        v = posed_vertices(body, animation, int(f))
        ratio = np.stack([np.linalg.norm(v[faces[:, b]] - v[faces[:, a]], axis=1) for a, b in corner], 1) / rest_len
        n = np.cross(v[faces[:, 1]] - v[faces[:, 0]], v[faces[:, 2]] - v[faces[:, 0]])
        carried = np.einsum("fab,fb->fa", animation.rotations[int(f)][owner], rest_n)
        flipped = (n * carried).sum(axis=1) < 0
        for name, m in sel.items():
            if not m.any():
                continue
            o = out[name]
            o["min_edge_ratio"] = min(o["min_edge_ratio"], float(ratio[m].min()))
            o["max_edge_ratio"] = max(o["max_edge_ratio"], float(ratio[m].max()))
            o["max_inverted_faces"] = max(o["max_inverted_faces"], int(flipped[m].sum()))
    return out
