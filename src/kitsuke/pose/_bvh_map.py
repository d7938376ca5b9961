"""Map a BVH skeleton onto the kitsuke joint set by naming rules, and convert units and axes (SPEC §2).

Naming rules (no per-file tables). A joint name is reduced to a side and a *base word*:
1. Namespaces and rig prefixes go: everything up to the last ':' or '|' (`mixamorig:LeftUpLeg`), and a leading
   `mixamorig`, `Bip01`/`Bip001`, `Character1_`, `CC_Base_`, `DEF-`.
2. The side: `Left…`/`Right…`, `…Left`/`…Right`, `L_…`, `…_L`, `….L`, `…-L` (either case), or a single `l`/`r`/`L`/`R`
   prefix when what follows is a known base word (`lThigh`, `LHipJoint`, `lhand`; but `lowerback` has no side).
3. The base word: lower case, letters only (digits and separators dropped: `upperleg01` → `upperleg`,
   `toe1-1` → `toe`), without a trailing `bend`/`twist` (DAZ Genesis `lShldrBend` → `shldr`).

Roles, per side, each searched below the previous one in the hierarchy (the first match nearest the root wins;
a lower-priority word only when no higher-priority one exists):
- hip: upleg, upperleg, thigh, femur; else hip (CMU ASF `LeftHip`; `LHipJoint` is a pelvis helper, not a hip).
- knee: leg, lowerleg, shin, calf, knee, tibia.  ankle: foot, ankle.
- shoulder (the upper arm's start): upperarm, arm, shldr, humerus; else shoulder (CMU ASF `LeftShoulder`).
- clavicle: collar, clavicle; else shoulder when the side also has an upper-arm word (Mixamo/CMU-BVH
  `LeftShoulder` above `LeftArm`).  elbow: forearm, lowerarm, elbow.  wrist: hand, wrist.
- neck: the first joint whose base contains `neck`; head: base `head`.
Character Creator / iClone names read by the same rules: `CC_Base_L_Thigh` → hip, `L_Calf` → knee, `L_Foot` →
ankle, `L_ToeBase` → toe, `L_Clavicle`, `L_Upperarm`, `L_Forearm`, `L_Hand`, `NeckTwist01` → neck, `Head`;
`Hip`, `Pelvis`, `Waist`, `Spine01/02` have no side and take no role (the pelvis is mid-hips, never a hip), and
twist helpers (`L_ThighTwist01` → thigh) lie below their bone, so the bone itself is nearer the root and wins.
Derived joints (documented where they are built): pelvis = mid-hips (as for MediaPipe); chest = the joint where the
two arm chains meet; clavicle = the collar joint, else a fifth of the way from the neck base to the shoulder;
spine = the joint on the root→chest path nearest the height halfway between pelvis and chest
(else the midpoint); head = the centre of the head (midpoint of the head joint and the highest reference-pose point
below it, carried rigidly with the head); toe = the ankle's farthest reference-pose descendant point (the toe tip),
unless that point is not in front of the ankle (an End Site straight below it, as in the CMU-on-MakeHuman kick);
heel = a `heel` joint if any, else a point fixed to the ankle 0.039·H below and 0.03·H behind it (H = standing
height; stature proportions of Drillis & Contini), and a missing toe likewise 0.12·H in front (see `_foot_points`).

Axes and units come from the animated frames, not from the zero pose alone: some rigs (Character Creator /
iClone) give their bones frames turned by about 180°, so that in the zero pose (all channels zero) the legs point
up and every frame's rotations fold them back down. They are decided on up to DECISION_FRAMES frames spread over
the whole clip, whatever `stride` and `max_frames` keep.
- Up: the mean over frames of head − mid-ankles, rounded to the nearest axis (±X, ±Y, ±Z; Z-up files are rotated
  to Y up); the zero pose's only when the frames give no direction.
- Facing: the skeleton is turned about Y so that its left hip is at +X (facing +Z), by the mean over frames of
  the hip line (left hip − right hip) rounded to the nearest quarter turn (see `_facing_turn` for why rounded).
- Reference pose (a pose where the skeleton stands, for the choices above and the height): the zero pose, except
  that a joint whose orientation over the clip is on average more than FOLD_DEG away from its zero-pose
  orientation (a folded bind frame) takes the axis-aligned orientation nearest that mean (`_reference_orientations`).
  Skeletons that stand in their zero pose (CMU, MakeHuman, DAZ, Mixamo) keep it unchanged.
- Units: the standing height (top of the head to the lowest foot point along up, in the reference pose; the
  median over frames of the posed skeleton's when even the reference pose does not stand) picks the file unit
  among m, dm, cm, mm, inch and CMU's ASF unit (1/0.45 inch) whose height in metres is nearest 1.7 m (ratio in log
  scale), unless a scale is given.
The poses' `source` records them: `up_axis`, `up_from`, `yaw_deg`, `units`, `rest_height_m` (the standing height),
`height_from`, `unfolded_joints` (the joints whose bind frame was found folded).
"""

from __future__ import annotations

import itertools
import math
import os
import re
from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..skeleton import INDEX, JOINTS
from ._bvh import BvhFile, forward_kinematics, read_bvh
from ._sequence import PoseSequence

_VOCAB: dict[str, list[tuple[str, ...]]] = {
    # role -> words by priority (first tuple preferred)
    "hip": [("upleg", "upperleg", "thigh", "femur"), ("hip",)],
    "knee": [("leg", "lowerleg", "shin", "calf", "knee", "tibia")],
    "ankle": [("foot", "ankle")],
    "heel": [("heel",)],
    "shoulder": [("upperarm", "arm", "shldr", "humerus"), ("shoulder",)],
    "clavicle": [("collar", "clavicle"), ("shoulder",)],
    "elbow": [("forearm", "lowerarm", "elbow")],
    "wrist": [("hand", "wrist")],
}
_KNOWN = {w for tiers in _VOCAB.values() for tier in tiers for w in tier} | {"hipjoint", "toe", "toebase", "fingers"}
_PREFIX = re.compile(r"^(mixamorig\d*|bip0*1|character\d*|cc_base|def)[_ .\-]*", re.IGNORECASE)
_SIDE_PREFIX = re.compile(r"^(left|right)[_ .\-]?(.+)$", re.IGNORECASE)
_SIDE_SUFFIX = re.compile(r"^(.+?)[_ .\-]?(left|right)$", re.IGNORECASE)
_SIDE_SHORT_PREFIX = re.compile(r"^([lrLR])[_ .\-](.+)$")
_SIDE_SHORT_SUFFIX = re.compile(r"^(.+?)[_ .\-]([lrLR])$")

#: Units the scale is picked from: name -> metres per unit.
UNITS: dict[str, float] = {
    "m": 1.0,
    "dm": 0.1,
    "cm": 0.01,
    "mm": 0.001,
    "inch": 0.0254,
    "cmu": 0.0254 / 0.45,
}


def _base(word: str) -> str:
    b = re.sub(r"[^a-z]", "", word.lower())
    for tail in ("bend", "twist"):
        if b.endswith(tail) and len(b) > len(tail):
            b = b[: -len(tail)]
    return b


def parse_joint_name(name: str) -> tuple[str | None, str]:
    """(side 'l' | 'r' | None, base word) of a BVH joint name, by the rules in the module docstring."""
    s = re.split(r"[:|]", name.strip())[-1]
    s = _PREFIX.sub("", s) or s
    for pattern, side_group, rest_group in (
        (_SIDE_PREFIX, 1, 2),
        (_SIDE_SUFFIX, 2, 1),
        (_SIDE_SHORT_PREFIX, 1, 2),
        (_SIDE_SHORT_SUFFIX, 2, 1),
    ):
        m = pattern.match(s)
        if m:
            return m.group(side_group)[0].lower(), _base(m.group(rest_group))
    if len(s) > 1 and s[0] in "lrLR" and _base(s[1:]) in _KNOWN:
        return s[0].lower(), _base(s[1:])
    return None, _base(s)


@dataclass(frozen=True)
class BvhMapping:
    """Which BVH joints give which kitsuke joints (indices into the BVH's joints; -1 when derived)."""

    joint_of: dict[str, int]
    chest: int
    spine: int
    neck: int
    head: int
    toe_point: dict[str, tuple[str, int]]  # side -> ("joint" | "end", index)
    heel_joint: dict[str, int]

    def describe(self, bvh: BvhFile) -> dict[str, str]:
        """kitsuke joint -> the BVH joint or rule it comes from (for the poses file's source)."""
        out = {"pelvis": "mid-hips"}
        for role, j in self.joint_of.items():
            out[role] = bvh.names[j]
        out["chest"] = bvh.names[self.chest]
        out["spine"] = bvh.names[self.spine] if self.spine >= 0 else "midpoint pelvis-chest"
        out["neck"] = bvh.names[self.neck] if self.neck >= 0 else "midpoint chest-head"
        out["head"] = f"centre of {bvh.names[self.head]}"
        for side in "lr":
            kind, idx = self.toe_point[side]
            out[f"{side}_toe"] = f"end of {bvh.names[bvh.end_parents[idx]]}" if kind == "end" else bvh.names[idx]
            h = self.heel_joint[side]
            out[f"{side}_heel"] = bvh.names[h] if h >= 0 else "derived from ankle"
        return dict(sorted(out.items(), key=lambda kv: INDEX.get(kv[0], 99)))


def _descendants(parents: np.ndarray, j: int) -> np.ndarray:
    """Boolean mask of the strict descendants of joint j (parents come before children)."""
    mask = np.zeros(len(parents), dtype=bool)
    for k in range(j + 1, len(parents)):
        p = parents[k]
        if p == j or (p >= 0 and mask[p]):
            mask[k] = True
    return mask


def _depth(parents: np.ndarray) -> np.ndarray:
    d = np.zeros(len(parents), dtype=np.int64)
    for k in range(len(parents)):
        d[k] = 0 if parents[k] < 0 else d[parents[k]] + 1
    return d


def _ancestors(parents: np.ndarray, j: int) -> list[int]:
    out = []
    while j >= 0:
        out.append(j)
        j = int(parents[j])
    return out


def map_bvh_joints(
    bvh: BvhFile,
    path: str | os.PathLike[str] = "<bvh>",
    *,
    reference: tuple[np.ndarray, np.ndarray] | None = None,
) -> BvhMapping:
    """Find the joint-set roles in a BVH skeleton; InputError listing what cannot be found.

    The roles come from the names alone; the toe point and the spine joint are chosen from the geometry of
    `reference`: (J, 3) joint and (E, 3) End Site positions (file units and axes) of a pose in which the skeleton
    stands, default the zero pose (`load_bvh` passes its reference pose, see `_reference_orientations`).
    """
    parsed = [parse_joint_name(n) for n in bvh.names]
    depth = _depth(bvh.parents)
    n_j = len(bvh.names)

    def find(role: str, side: str | None, within: np.ndarray | None, exclude: set[int] = frozenset()) -> int:  # type: ignore[assignment]
        for tier in _VOCAB[role]:
            cands = [
                k
                for k, (sd, base) in enumerate(parsed)
                if base in tier and sd == side and k not in exclude and (within is None or within[k])
            ]
            if cands:
                return min(cands, key=lambda k: (depth[k], k))
        return -1

    joint_of: dict[str, int] = {}
    missing: list[str] = []
    for side in "lr":
        hip = find("hip", side, None)
        knee = find("knee", side, _descendants(bvh.parents, hip)) if hip >= 0 else -1
        ankle = find("ankle", side, _descendants(bvh.parents, knee)) if knee >= 0 else -1
        upper = find("shoulder", side, None)
        clav = -1
        if upper >= 0:
            anc = np.zeros(n_j, dtype=bool)
            anc[_ancestors(bvh.parents, int(bvh.parents[upper]))] = True
            clav = find("clavicle", side, anc, exclude={upper})
        elbow = find("elbow", side, _descendants(bvh.parents, upper)) if upper >= 0 else -1
        wrist = find("wrist", side, _descendants(bvh.parents, elbow)) if elbow >= 0 else -1
        for role, j in (
            ("hip", hip),
            ("knee", knee),
            ("ankle", ankle),
            ("shoulder", upper),
            ("elbow", elbow),
            ("wrist", wrist),
            ("clavicle", clav),
        ):
            if j >= 0:
                joint_of[f"{side}_{role}"] = j
            elif role != "clavicle":
                missing.append(f"{side}_{role}")
    head = next((k for k, (sd, b) in enumerate(parsed) if sd is None and b == "head"), -1)
    if head < 0:
        missing.append("head")
    if missing:
        names = ", ".join(bvh.names[:40]) + (" ..." if n_j > 40 else "")
        raise InputError(
            f"cannot map BVH joints to the kitsuke joint set: no joint found for {', '.join(missing)} "
            f"(the file has: {names})",
            path,
        )

    # chest: where the two arm chains meet (the deepest common ancestor of the two upper arms)
    left_anc = set(_ancestors(bvh.parents, joint_of["l_shoulder"]))
    chest = next(k for k in _ancestors(bvh.parents, joint_of["r_shoulder"]) if k in left_anc)
    neck = -1
    below_chest = _descendants(bvh.parents, chest)
    necks = [k for k, (sd, b) in enumerate(parsed) if sd is None and "neck" in b and below_chest[k]]
    if necks:
        neck = min(necks, key=lambda k: (depth[k], k))
    elif bvh.parents[head] >= 0 and below_chest[bvh.parents[head]]:
        neck = int(bvh.parents[head])

    toe_point: dict[str, tuple[str, int]] = {}
    heel_joint: dict[str, int] = {}
    if reference is None:
        rest_pos, _, rest_end = forward_kinematics(bvh, rest=True)
        ref_pos, ref_end = rest_pos[0], rest_end[0]
    else:
        ref_pos, ref_end = reference
    for side in "lr":
        ankle = joint_of[f"{side}_ankle"]
        below = _descendants(bvh.parents, ankle)
        pts = [("joint", k, ref_pos[k]) for k in np.flatnonzero(below)]
        pts += [
            ("end", e, ref_end[e])
            for e in range(len(bvh.end_parents))
            if bvh.end_parents[e] == ankle or below[bvh.end_parents[e]]
        ]
        if not pts:
            raise InputError(f"cannot map BVH joints: the {side} ankle has no foot below it", path)
        kind, idx, _ = max(pts, key=lambda t: float(np.linalg.norm(t[2] - ref_pos[ankle])))
        toe_point[side] = (kind, int(idx))
        heel = find("heel", side, below)
        heel_joint[side] = heel

    # spine: the joint between root and chest nearest half the pelvis→chest height (reference pose)
    path_joints = _ancestors(bvh.parents, chest)[1:-1]  # strictly between chest and root
    spine = -1
    if path_joints:
        pelvis_ref = 0.5 * (ref_pos[joint_of["l_hip"]] + ref_pos[joint_of["r_hip"]])
        mid = 0.5 * (pelvis_ref + ref_pos[chest])
        spine = min(path_joints, key=lambda k: float(np.linalg.norm(ref_pos[k] - mid)))
    return BvhMapping(joint_of, chest, spine, neck, head, toe_point, heel_joint)


def _rotation_to_y_up(up: np.ndarray) -> np.ndarray:
    """Proper rotation taking the given coordinate axis direction (±X, ±Y, ±Z) to +Y."""
    axis = int(np.argmax(np.abs(up)))
    sign = 1.0 if up[axis] > 0 else -1.0
    table = {
        (1, 1.0): np.eye(3),
        (1, -1.0): np.diag([1.0, -1.0, -1.0]),
        (2, 1.0): np.array([[1.0, 0, 0], [0, 0, 1], [0, -1, 0]]),  # (x, y, z) -> (x, z, -y)
        (2, -1.0): np.array([[1.0, 0, 0], [0, 0, -1], [0, 1, 0]]),  # (x, y, z) -> (x, -z, y)
        (0, 1.0): np.array([[0.0, -1, 0], [1, 0, 0], [0, 0, 1]]),  # (x, y, z) -> (-y, x, z)
        (0, -1.0): np.array([[0.0, 1, 0], [-1, 0, 0], [0, 0, 1]]),  # (x, y, z) -> (y, -x, z)
    }
    return table[(axis, sign)]


def _axis_name(up: np.ndarray) -> str:
    axis = int(np.argmax(np.abs(up)))
    return ("+" if up[axis] > 0 else "-") + "XYZ"[axis]


#: At most this many frames, evenly spread over the whole clip, decide the axes, the reference pose and the height
#: (whatever `stride` and `max_frames` keep, so that a part of a clip is read in the same axes as the whole).
DECISION_FRAMES = 512
#: A joint whose mean orientation over the clip is farther than this from its zero-pose orientation has a folded
#: bind frame (Character Creator legs: about 180°); motion alone keeps the joints that matter nearer (a seated
#: thigh is about 90° from standing).
FOLD_DEG = 120.0


def _cube_rotations() -> np.ndarray:
    """(24, 3, 3): the rotations that map the coordinate axes onto themselves (signed permutations, det +1)."""
    out = []
    for perm in itertools.permutations(range(3)):
        for signs in itertools.product((1.0, -1.0), repeat=3):
            m = np.zeros((3, 3))
            m[np.arange(3), perm] = signs
            if np.linalg.det(m) > 0:
                out.append(m)
    return np.array(out)


_CUBE = _cube_rotations()


def _decision_frames(n: int) -> np.ndarray:
    """Indices of at most DECISION_FRAMES frames spread evenly over a clip of n frames."""
    return np.unique(np.linspace(0, n - 1, min(n, DECISION_FRAMES)).round().astype(np.int64))


def _subtree(bvh: BvhFile, j: int) -> tuple[np.ndarray, np.ndarray]:
    """Joint j's strict descendants (J,) and the End Sites on j or below it (E,), as boolean masks."""
    below = _descendants(bvh.parents, j)
    ends = (bvh.end_parents == j) | below[bvh.end_parents]
    return below, ends


def _up_vector(
    pos: np.ndarray, rest_pos: np.ndarray, mapping: BvhMapping, path: str | os.PathLike[str]
) -> tuple[np.ndarray, str]:
    """The direction in which the head stays above the feet, (3,) file axes (not normalised), and where it came from.

    pos : (n, J, 3) joint positions over the decision frames; rest_pos : (J, 3) the zero pose.
    The mean over frames of head − mid-ankles: the animated skeleton stands whatever its zero pose does (rigs whose
    zero pose folds the legs up, as Character Creator's, read upside down from the zero pose). The zero pose only
    when the frames cancel out (nothing to go by).
    """
    jo = mapping.joint_of

    def head_over_ankles(p: np.ndarray) -> np.ndarray:
        return p[..., mapping.head, :] - 0.5 * (p[..., jo["l_ankle"], :] + p[..., jo["r_ankle"], :])

    v = head_over_ankles(pos)
    up = v.mean(axis=0)
    if np.linalg.norm(up) > 1e-9 * np.linalg.norm(v, axis=1).mean():
        return up, "motion"
    up = head_over_ankles(rest_pos)
    if not np.linalg.norm(up) > 0:
        raise InputError("the head stays at the ankles in every frame and the zero pose; cannot find the up axis", path)
    return up, "zero pose"


def _facing_turn(hip_y: np.ndarray) -> tuple[np.ndarray, float]:
    """The turn about Y that puts the person's left at +X: (3, 3), and its angle in radians (a multiple of π/2).

    hip_y : (n, 3) left hip − right hip over the decision frames, in Y-up axes. Their mean's heading is rounded to
    the nearest quarter turn: mocap files are written along their axes, while a person turns during a clip (the
    CMU kick's mean hip line is 22° off its run-up, the walk's −16° off its path), so the nearest axis recovers the
    file's forward where the exact mean would not. The first frame decides when the mean has no heading.
    """
    h = hip_y.mean(axis=0)
    if not math.hypot(h[0], h[2]) > 1e-9 * np.linalg.norm(hip_y, axis=1).mean():
        h = hip_y[0]  # turns evenly all round: nothing better than where it starts
    quarter = round(math.atan2(h[2], h[0]) / (math.pi / 2)) % 4
    c, s = ((1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0))[quarter]
    turn = np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])  # takes (cos yaw, ., sin yaw) to +X
    return turn, math.pi / 2 * (quarter if quarter < 3 else -1)


def _reference_orientations(rot: np.ndarray, hip_out: np.ndarray, axes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each joint's world orientation in a pose where the skeleton stands: (J, 3, 3) file axes, and (J,) folded.

    rot : (n, J, 3, 3) world rotations over the decision frames (file axes); hip_out : (n, 3) hip lines in output
    axes (Y up, facing +Z); axes : (3, 3) rotation from file to output axes.
    Each frame's turn about Y (its hip line's heading) is taken out first, so that a walk that turns round averages
    like one that does not. A joint whose mean orientation over the clip lies within FOLD_DEG of the zero pose
    keeps the zero pose (identity: skeletons that already stood in their zero pose are read exactly as before);
    a farther one has a folded bind frame and takes the axis-aligned rotation nearest its mean. Bind frames differ
    between rigs by such rotations, so the reference pose (and every choice made in it) is the same for a clip
    written on either rig.
    """
    psi = np.arctan2(hip_out[:, 2], hip_out[:, 0])
    c, s = np.cos(psi), np.sin(psi)
    heading = np.zeros((len(psi), 3, 3))  # about Y, taking +X to the frame's hip direction
    heading[:, 0, 0], heading[:, 0, 2], heading[:, 1, 1] = c, -s, 1.0
    heading[:, 2, 0], heading[:, 2, 2] = s, c
    untwist = np.einsum("ba,ncb,cd->nad", axes, heading, axes)  # axesᵀ·headingᵀ·axes: un-turn, in file axes
    mean = np.einsum("nab,njbc->jac", untwist, rot) / len(rot)
    u, _, vt = np.linalg.svd(mean)
    u[:, :, 2] *= np.linalg.det(u @ vt)[:, None]  # the nearest proper rotation (chordal mean)
    nearest = u @ vt
    cos = np.clip((np.trace(nearest, axis1=1, axis2=2) - 1.0) / 2.0, -1.0, 1.0)
    folded = np.degrees(np.arccos(cos)) > FOLD_DEG
    snapped = _CUBE[np.argmax(np.einsum("kab,jab->jk", _CUBE, nearest), axis=1)]
    return np.where(folded[:, None, None], snapped, np.eye(3)), folded


def _pose_with_orientations(bvh: BvhFile, orient: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Joint (J, 3) and End Site (E, 3) positions, file units, of the skeleton with the given world orientations
    (J, 3, 3), root at the origin (the zero pose for identities)."""
    pos = np.zeros((len(bvh.names), 3))
    for j, par in enumerate(bvh.parents):
        if par >= 0:
            pos[j] = pos[par] + orient[par] @ bvh.offsets[j]
    end = pos[bvh.end_parents] + np.einsum("eij,ej->ei", orient[bvh.end_parents], bvh.end_offsets)
    return pos, end


def _height(bvh: BvhFile, mapping: BvhMapping, up: np.ndarray, pos: np.ndarray, end: np.ndarray) -> np.ndarray:
    """Top of the head to the lowest foot point along `up` (3,), file units: (n,) for (n, J, 3)/(n, E, 3) poses."""
    head_j, head_e = _subtree(bvh, mapping.head)
    head_j[mapping.head] = True
    foot_j = np.zeros(len(bvh.names), dtype=bool)
    foot_e = np.zeros(len(bvh.end_parents), dtype=bool)
    for side in "lr":
        ankle = mapping.joint_of[f"{side}_ankle"]
        below, ends = _subtree(bvh, ankle)
        foot_j |= below
        foot_j[ankle] = True
        foot_e |= ends
    h_pos, h_end = pos @ up, end @ up
    top = np.maximum(h_pos[:, head_j].max(axis=1), h_end[:, head_e].max(axis=1, initial=-np.inf))
    bottom = np.minimum(h_pos[:, foot_j].min(axis=1), h_end[:, foot_e].min(axis=1, initial=np.inf))
    return top - bottom


def _stands(mapping: BvhMapping, up: np.ndarray, pos: np.ndarray) -> bool:
    """Whether a pose (J, 3) has, along `up`, the head above the hips and the hips above both ankles."""
    jo = mapping.joint_of
    h = pos @ up
    hips = 0.5 * (h[jo["l_hip"]] + h[jo["r_hip"]])
    return bool(h[mapping.head] > hips > max(h[jo["l_ankle"]], h[jo["r_ankle"]]))


def load_bvh(
    path: str | os.PathLike[str],
    *,
    scale: float | None = None,
    stride: int = 1,
    max_frames: int | None = None,
) -> PoseSequence:
    """Read a BVH file as a `PoseSequence` in metres, Y up, facing +Z, by the rules of this module.

    Parameters
    ----------
    scale : metres per file unit; default: picked from the standing height (module docstring).
    stride : keep every `stride`-th frame.  max_frames : keep at most this many frames.

    The axes, the height and the reference pose are decided on the whole clip, whatever frames are kept.
    InputError for unreadable files, and for skeletons whose names cannot be mapped (listing what is missing).
    """
    if stride < 1:
        raise InputError(f"stride must be at least 1, got {stride}", path)
    bvh = read_bvh(path)
    roles = map_bvh_joints(bvh, path)  # the names' roles; toe and spine are chosen again in the reference pose
    frames = np.arange(0, bvh.n_frames, stride)
    if max_frames is not None:
        frames = frames[: max(0, int(max_frames))]
    if len(frames) == 0:
        raise InputError("no frames selected", path)

    # axes: up, then facing, from the animated skeleton (module docstring)
    rest_pos, _, _ = forward_kinematics(bvh, rest=True)
    decision = _decision_frames(bvh.n_frames)
    d_pos, d_rot, d_end = forward_kinematics(bvh, decision)
    with np.errstate(all="ignore"):
        # Finite numbers can still overflow through the offsets and rotations (1e308-sized values), and sums of
        # positions near that size overflow in the decisions below: such files are no skeleton.
        bad = ~((np.abs(d_pos) < 1e300).all(axis=(1, 2)) & (np.abs(d_end) < 1e300).all(axis=(1, 2)))
    if bad.any():
        raise InputError(f"frame {int(decision[np.argmax(bad)])}: joint positions overflow (values too large)", path)
    up_vec, up_from = _up_vector(d_pos, rest_pos[0], roles, path)
    to_y = _rotation_to_y_up(up_vec)
    jo = roles.joint_of
    hip_y = (d_pos[:, jo["l_hip"]] - d_pos[:, jo["r_hip"]]) @ to_y.T
    turn, yaw = _facing_turn(hip_y)
    axes = turn @ to_y  # file axes -> Y up, facing +Z (a signed permutation)

    # the reference pose: the zero pose with folded bind frames turned as the clip holds them
    orient, folded = _reference_orientations(d_rot, hip_y @ turn.T, axes)
    ref_pos, ref_end = _pose_with_orientations(bvh, orient)
    mapping = map_bvh_joints(bvh, path, reference=(ref_pos, ref_end))
    up_file = to_y[1]  # the file-axes direction that becomes +Y
    if _stands(mapping, up_file, ref_pos):
        height_units = float(_height(bvh, mapping, up_file, ref_pos[None], ref_end[None])[0])
        height_from = "reference pose"
    else:
        # a bind frame too far from any axis to be unfolded: the posed skeleton is all there is
        height_units = float(np.median(_height(bvh, mapping, up_file, d_pos, d_end)))
        height_from = "posed frames (median)"
    if not height_units > 0:
        raise InputError("the skeleton has no height", path)
    if scale is None:
        unit = min(UNITS, key=lambda u: abs(math.log(height_units * UNITS[u] / 1.7)))
        s = UNITS[unit]
    else:
        if not (scale > 0 and math.isfinite(scale)):
            raise InputError(f"scale must be a positive number of metres per unit, got {scale}", path)
        unit, s = "given", float(scale)
    conv = s * axes  # file units/axes -> metres, Y up, facing +Z

    pos, rot, end = forward_kinematics(bvh, frames)
    out = np.empty((len(frames), len(JOINTS), 3))

    def put(name: str, xyz_file: np.ndarray) -> None:
        out[:, INDEX[name]] = xyz_file @ conv.T

    def carried(j: int, local: np.ndarray) -> np.ndarray:
        """(n, 3) file-axes positions of a point fixed to joint j's frame at `local` (3,) from it."""
        return pos[:, j] + np.einsum("nij,j->ni", rot[:, j], local)

    for name, j in jo.items():
        put(name, pos[:, j])
    put("pelvis", 0.5 * (pos[:, jo["l_hip"]] + pos[:, jo["r_hip"]]))
    put("chest", pos[:, mapping.chest])
    if mapping.spine >= 0:
        put("spine", pos[:, mapping.spine])
    else:
        put("spine", 0.5 * (0.5 * (pos[:, jo["l_hip"]] + pos[:, jo["r_hip"]]) + pos[:, mapping.chest]))
    put("head", carried(mapping.head, _head_centre_local(bvh, mapping, ref_pos, ref_end, orient, up_file)))
    if mapping.neck >= 0:
        put("neck", pos[:, mapping.neck])
    else:
        put("neck", 0.5 * (pos[:, mapping.chest] + pos[:, mapping.head]))
    derived_feet: dict[str, bool] = {}
    for side in "lr":
        if f"{side}_clavicle" not in jo:
            # no collar bone: a point a fifth of the way from the neck base towards the shoulder
            put(f"{side}_clavicle", 0.8 * out_file_neck(pos, mapping) + 0.2 * pos[:, jo[f"{side}_shoulder"]])
        ankle = jo[f"{side}_ankle"]
        toe_derived, heel_local, toe_local = _foot_points(
            mapping, side, ref_pos, ref_end, orient, to_y, turn, height_units
        )
        if toe_derived:
            put(f"{side}_toe", carried(ankle, toe_local))
        else:
            kind, idx = mapping.toe_point[side]
            put(f"{side}_toe", end[:, idx] if kind == "end" else pos[:, idx])
        if mapping.heel_joint[side] >= 0:
            put(f"{side}_heel", pos[:, mapping.heel_joint[side]])
        else:
            put(f"{side}_heel", carried(ankle, heel_local))
        derived_feet[side] = toe_derived

    with np.errstate(all="ignore"):
        bad = ~np.isfinite(out).all(axis=(1, 2))
    if bad.any():
        # Finite numbers can still overflow through the offsets and rotations (1e308-sized values).
        raise InputError(f"frame {int(frames[np.argmax(bad)])}: joint positions overflow (values too large)", path)
    source = {
        "kind": "bvh",
        "path": str(path),
        "frames": int(bvh.n_frames),
        "fps": float(bvh.fps),
        "stride": int(stride),
        "units": unit,
        "metres_per_unit": s,
        "rest_height_m": round(height_units * s, 4),
        "height_from": height_from,
        "up_axis": _axis_name(up_vec),
        "up_from": up_from,
        "yaw_deg": round(math.degrees(yaw), 3),
        "unfolded_joints": [bvh.names[k] for k in np.flatnonzero(folded)],
        "joint_map": mapping.describe(bvh),
    }
    for side in "lr":
        if derived_feet[side]:
            source["joint_map"][f"{side}_toe"] = "derived from ankle (no toe in the skeleton)"
    return PoseSequence(
        positions=out,
        valid=np.ones(len(frames), dtype=bool),
        times=frames * bvh.frame_time,
        fps=float(bvh.fps) / stride,
        source=source,
    )


def _head_centre_local(
    bvh: BvhFile,
    mapping: BvhMapping,
    ref_pos: np.ndarray,
    ref_end: np.ndarray,
    orient: np.ndarray,
    up: np.ndarray,
) -> np.ndarray:
    """(3,) the head centre in the head joint's frame, file units: half way from the head joint to the highest
    point below it in the reference pose (`up` (3,) in file axes), zero when nothing is below the head."""
    h = mapping.head
    below, ends = _subtree(bvh, h)
    cand = np.concatenate([ref_pos[below], ref_end[ends]])
    if not len(cand):
        return np.zeros(3)
    top = cand[int(np.argmax(cand @ up))]
    return 0.5 * orient[h].T @ (top - ref_pos[h])  # reference world offset -> the head's own frame


#: Anthropometric proportions of stature (Drillis & Contini): ankle height above the sole, heel behind the ankle,
#: toe tip in front of the ankle (foot length 0.152 minus the heel part).
ANKLE_HEIGHT = 0.039
HEEL_BACK = 0.03
TOE_FRONT = 0.12


def _foot_points(
    mapping: BvhMapping,
    side: str,
    ref_pos: np.ndarray,
    ref_end: np.ndarray,
    orient: np.ndarray,
    to_y: np.ndarray,
    turn: np.ndarray,
    height_units: float,
) -> tuple[bool, np.ndarray, np.ndarray]:
    """Heel (and, for skeletons without a forward toe, toe) as points fixed to the ankle joint's frame.

    In the reference pose (ref_pos (J, 3), ref_end (E, 3), world orientations orient (J, 3, 3), file units and
    axes) the heel lies ANKLE_HEIGHT·H below the ankle and HEEL_BACK·H behind it, "behind" being against the
    horizontal ankle→toe direction (H = standing height, file units). When the farthest point below the ankle is not
    in front of it (less than 2 % of H horizontally, e.g. an End Site straight under the ankle) the toe is derived
    the same way, TOE_FRONT·H in front of the ankle along the facing direction (+Z after conversion), at the sole.
    Returns (toe derived?, heel offset (3,), toe offset (3,)), in the ankle's own frame, file units.
    """
    ankle = mapping.joint_of[f"{side}_ankle"]
    kind, idx = mapping.toe_point[side]
    toe_ref = ref_end[idx] if kind == "end" else ref_pos[idx]
    fwd = (toe_ref - ref_pos[ankle]) @ to_y.T
    fwd[1] = 0.0
    derived = float(np.linalg.norm(fwd)) < 0.02 * height_units
    if derived:
        fwd = turn.T @ np.array([0.0, 0.0, 1.0])  # facing direction (+Z after the turn), in Y-up axes
    fwd = fwd / np.linalg.norm(fwd)
    down = np.array([0.0, -ANKLE_HEIGHT * height_units, 0.0])
    to_local = orient[ankle].T  # reference world offset -> the ankle's own frame
    heel_local = to_local @ ((down - HEEL_BACK * height_units * fwd) @ to_y)  # Y-up axes back to file axes
    toe_local = to_local @ ((down + TOE_FRONT * height_units * fwd) @ to_y)
    return derived, heel_local, toe_local


def out_file_neck(pos: np.ndarray, mapping: BvhMapping) -> np.ndarray:
    """(n, 3) file-frame position of the neck base as `load_bvh` defines it."""
    if mapping.neck >= 0:
        return pos[:, mapping.neck]
    return 0.5 * (pos[:, mapping.chest] + pos[:, mapping.head])
