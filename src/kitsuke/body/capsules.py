"""Capsules ("bones" in the paper) fitted inside the body along the rig, for cloth collision with thin parts."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..skeleton import INDEX
from .rig import Rig

#: (capsule name, start joint, end joint): limbs, neck and torso.
CAPSULE_BONES: tuple[tuple[str, str, str], ...] = (
    ("torso", "pelvis", "chest"),
    ("neck", "neck", "head"),
    ("l_upper_arm", "l_shoulder", "l_elbow"),
    ("l_forearm", "l_elbow", "l_wrist"),
    ("r_upper_arm", "r_shoulder", "r_elbow"),
    ("r_forearm", "r_elbow", "r_wrist"),
    ("l_thigh", "l_hip", "l_knee"),
    ("l_shin", "l_knee", "l_ankle"),
    ("r_thigh", "r_hip", "r_knee"),
    ("r_shin", "r_knee", "r_ankle"),
)

#: Which low percentile of the skin's distance from the axis, per slice along the bone, bounds the radius: low enough
#: that the capsule stays inside the flesh, high enough to stop cloth edges cutting through the limb.
RADIUS_PERCENTILE = 5.0
#: Slices along the bone (between 10 % and 90 % of its length) for the tapered radius fit.
N_SLICES = 8


@dataclass
class Capsule:
    """A tapered capsule along the bone between two joints: a segment swept by a sphere whose radius goes
    linearly from `radius_a_m` at joint_a to `radius_b_m` at joint_b (metres) — limbs narrow toward knee and wrist.

    offset_m : (3,) float64, metres, rest frame: the capsule's axis is the bone shifted by this vector (rotating with
        joint_a), because joints are not always at the middle of the flesh (the spine lies near the back).
    """

    name: str
    joint_a: str
    joint_b: str
    radius_a_m: float
    radius_b_m: float
    offset_m: np.ndarray = field(default_factory=lambda: np.zeros(3))


def segment_distance(points: np.ndarray, a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Distance of points (n, 3) from segment a-b, and the parameter t in [0, 1] of the closest point."""
    ab = b - a
    t = np.clip((points - a) @ ab / max(ab @ ab, 1e-300), 0.0, 1.0)
    return np.linalg.norm(points - (a + t[:, None] * ab), axis=1), t


def fit_capsules(vertices: np.ndarray, rig: Rig) -> list[Capsule]:
    """Fit one capsule per CAPSULE_BONES entry to rest `vertices` (V, 3).

    For each bone, the skin vertices mostly driven by its start joint and lying along the middle 80 % of the bone
    form a tube; the capsule axis is moved to the tube's centroid (the offset). In slices along the bone the
    RADIUS_PERCENTILE-th percentile of the skin's distance from the axis is measured, and the radius line is the
    least-squares line through those, lowered until it is under every slice: the capsule stays inside the flesh.
    """
    dominant = rig.weights.argmax(axis=1)
    capsules = []
    for name, ja, jb in CAPSULE_BONES:
        a, b = rig.joints[INDEX[ja]], rig.joints[INDEX[jb]]
        owners = [INDEX[ja]] if name != "torso" else [INDEX["pelvis"], INDEX["spine"]]
        pts = vertices[np.isin(dominant, owners)]
        _, t = segment_distance(pts, a, b)
        inner = (t > 0.1) & (t < 0.9)
        ring, t = pts[inner], t[inner]
        if len(ring) < 4 * N_SLICES:
            capsules.append(Capsule(name, ja, jb, 0.01, 0.01))
            continue
        axis = (b - a) / np.linalg.norm(b - a)
        rel = ring - a
        offset = (rel - np.outer(rel @ axis, axis)).mean(axis=0)
        d, _ = segment_distance(ring, a + offset, b + offset)
        edges = np.linspace(0.1, 0.9, N_SLICES + 1)
        tk, rk = [], []
        for lo, hi in zip(edges[:-1], edges[1:]):
            sel = (t >= lo) & (t < hi)
            if sel.sum() >= 4:
                tk.append(0.5 * (lo + hi))
                rk.append(np.percentile(d[sel], RADIUS_PERCENTILE))
        tk, rk = np.array(tk), np.array(rk)
        slope, icpt = np.polyfit(tk, rk, 1)
        icpt -= max(0.0, float((icpt + slope * tk - rk).max()))
        ra, rb = max(icpt, 0.005), max(icpt + slope, 0.005)
        capsules.append(Capsule(name, ja, jb, float(ra), float(rb), offset))
    return capsules


def capsule_segments(
    capsules: list[Capsule], joints: np.ndarray, rotations: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Endpoints (n, 2, 3) and end radii (n, 2), metres, of capsules for joint positions (J, 3), rest or posed.

    rotations : (J, 3, 3) world joint rotations of the pose (None = rest), to turn each capsule's offset.
    """
    ends = np.zeros((len(capsules), 2, 3))
    for i, c in enumerate(capsules):
        ia, ib = INDEX[c.joint_a], INDEX[c.joint_b]
        off = c.offset_m if rotations is None else rotations[ia] @ c.offset_m
        ends[i] = joints[ia] + off, joints[ib] + off
    return ends, np.array([[c.radius_a_m, c.radius_b_m] for c in capsules]).reshape(-1, 2)
