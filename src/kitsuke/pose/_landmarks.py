"""MediaPipe's 33 pose landmarks → the kitsuke joint set (pure numpy; no mediapipe import).

Coordinates. MediaPipe's world landmarks are metres, centred between the hips, x toward the image's right, y down,
z away from the camera (x, y, z right-handed). kitsuke is Y up with the person facing +Z and their left at +X
(SPEC §2). A person facing the camera has their left on the image's right, so the kitsuke frame is MediaPipe's
turned half a turn about x: (X, Y, Z) = (x, −y, −z). That is a rotation, not a mirror: left stays left. (A
mirrored "selfie" image would swap the person's sides; kitsuke always processes frames unmirrored and mirrors
only the displayed output.)

Joints (landmark numbers of MediaPipe's pose model; lerp(a, b, t) = a + t·(b − a)):
- pelvis = mid-hips (23, 24): MediaPipe's own origin.
- spine = lerp(pelvis, mid-shoulders, 0.35); chest = lerp(pelvis, mid-shoulders, 0.75): the lumbar and upper
  thoracic spine, which MediaPipe does not see, placed on the line between the hip and shoulder centres.
- neck = lerp(mid-shoulders, head, 0.2): the base of the neck, just above the shoulder line.
- head = mid-ears (7, 8): the centre of the head.
- l/r_clavicle = lerp(mid-shoulders, shoulder, 0.2): the inner end of the collar bone, on the shoulder line.
- l/r_shoulder 11/12, elbow 13/14, wrist 15/16, hip 23/24, knee 25/26, ankle 27/28, heel 29/30, toe = foot
  index 31/32 (the tip of the foot).
Image points are mapped with the same weights (pixel u, v); a mapped joint's visibility is the smallest of the
visibilities of the landmarks it is made from.
"""

from __future__ import annotations

import numpy as np

from ..skeleton import INDEX, JOINTS

#: MediaPipe pose landmark names, in the model's order (33).
LANDMARKS: tuple[str, ...] = (
    "nose",
    "left_eye_inner",
    "left_eye",
    "left_eye_outer",
    "right_eye_inner",
    "right_eye",
    "right_eye_outer",
    "left_ear",
    "right_ear",
    "mouth_left",
    "mouth_right",
    "left_shoulder",
    "right_shoulder",
    "left_elbow",
    "right_elbow",
    "left_wrist",
    "right_wrist",
    "left_pinky",
    "right_pinky",
    "left_index",
    "right_index",
    "left_thumb",
    "right_thumb",
    "left_hip",
    "right_hip",
    "left_knee",
    "right_knee",
    "left_ankle",
    "right_ankle",
    "left_heel",
    "right_heel",
    "left_foot_index",
    "right_foot_index",
)

#: Fractions used by the mapping (see the module docstring).
SPINE_T = 0.35
CHEST_T = 0.75
NECK_T = 0.2
CLAVICLE_T = 0.2


def _weights() -> np.ndarray:
    """(23, 33) float64: each joint as a weighted sum of landmarks (rows sum to 1)."""
    w = np.zeros((len(JOINTS), len(LANDMARKS)))
    lm = {name: i for i, name in enumerate(LANDMARKS)}

    def vec(*pairs: tuple[str, float]) -> np.ndarray:
        v = np.zeros(len(LANDMARKS))
        for name, weight in pairs:
            v[lm[name]] += weight
        return v

    mid_hips = vec(("left_hip", 0.5), ("right_hip", 0.5))
    mid_sh = vec(("left_shoulder", 0.5), ("right_shoulder", 0.5))
    head = vec(("left_ear", 0.5), ("right_ear", 0.5))
    rows = {
        "pelvis": mid_hips,
        "spine": (1 - SPINE_T) * mid_hips + SPINE_T * mid_sh,
        "chest": (1 - CHEST_T) * mid_hips + CHEST_T * mid_sh,
        "neck": (1 - NECK_T) * mid_sh + NECK_T * head,
        "head": head,
    }
    for side, word in (("l", "left"), ("r", "right")):
        rows[f"{side}_clavicle"] = (1 - CLAVICLE_T) * mid_sh + CLAVICLE_T * vec((f"{word}_shoulder", 1.0))
        for joint, landmark in (
            ("shoulder", "shoulder"),
            ("elbow", "elbow"),
            ("wrist", "wrist"),
            ("hip", "hip"),
            ("knee", "knee"),
            ("ankle", "ankle"),
            ("heel", "heel"),
            ("toe", "foot_index"),
        ):
            rows[f"{side}_{joint}"] = vec((f"{word}_{landmark}", 1.0))
    for name, row in rows.items():
        w[INDEX[name]] = row
    return w


#: (23, 33) float64 landmark → joint weights.
WEIGHTS: np.ndarray = _weights()

#: Turns MediaPipe world axes (x right, y down, z away) into kitsuke's (X = x, Y = −y, Z = −z).
MEDIAPIPE_TO_KITSUKE: np.ndarray = np.diag([1.0, -1.0, -1.0])


def world_to_joints(world: np.ndarray) -> np.ndarray:
    """(..., 33, 3) MediaPipe world landmarks (metres, y down) → (..., 23, 3) joints, metres, Y up, facing +Z."""
    world = np.asarray(world, dtype=np.float64)
    return np.einsum("jl,...lc->...jc", WEIGHTS, world) @ MEDIAPIPE_TO_KITSUKE.T


def image_to_joints(image: np.ndarray) -> np.ndarray:
    """(..., 33, 3) landmark pixels u, v and visibility → (..., 23, 3) joint pixels u, v and visibility."""
    image = np.asarray(image, dtype=np.float64)
    uv = np.einsum("jl,...lc->...jc", WEIGHTS, image[..., :2])
    vis = image[..., 2]
    used = WEIGHTS > 0
    # smallest visibility among the landmarks each joint uses
    vis_j = np.where(used, vis[..., None, :], np.inf).min(axis=-1)
    return np.concatenate([uv, vis_j[..., None]], axis=-1)
