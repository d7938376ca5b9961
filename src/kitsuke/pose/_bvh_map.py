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
Derived joints (documented where they are built): pelvis = mid-hips (as for MediaPipe); chest = the joint where the
two arm chains meet; clavicle = the collar joint, else a fifth of the way from the neck base to the shoulder;
spine = the joint on the root→chest path nearest the height halfway between pelvis and chest
(else the midpoint); head = the centre of the head (midpoint of the head joint and the highest rest-pose point
below it, carried rigidly with the head); toe = the ankle's farthest rest-pose descendant point (the toe tip),
unless that point is not in front of the ankle (an End Site straight below it, as in the CMU-on-MakeHuman kick);
heel = a `heel` joint if any, else a point fixed to the ankle 0.039·H below and 0.03·H behind it (H = rest height;
stature proportions of Drillis & Contini), and a missing toe likewise 0.12·H in front (see `_foot_points`).

Units: the rest-pose height (top of the head to the lowest foot point) picks the file unit among m, dm, cm, mm,
inch and CMU's ASF unit (1/0.45 inch) whose height in metres is nearest 1.7 m (ratio in log scale), unless a scale
is given. Axes: the up axis is the rest pose's ankles→head direction (Z-up files are rotated to Y up), then the
skeleton is turned about Y so that in the rest pose its left hip is at +X (facing +Z).
"""

from __future__ import annotations

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


def map_bvh_joints(bvh: BvhFile, path: str | os.PathLike[str] = "<bvh>") -> BvhMapping:
    """Find the joint-set roles in a BVH skeleton; InputError listing what cannot be found."""
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
    rest_pos, _, rest_end = forward_kinematics(bvh, rest=True)
    for side in "lr":
        ankle = joint_of[f"{side}_ankle"]
        below = _descendants(bvh.parents, ankle)
        pts = [("joint", k, rest_pos[0, k]) for k in np.flatnonzero(below)]
        pts += [
            ("end", e, rest_end[0, e])
            for e in range(len(bvh.end_parents))
            if bvh.end_parents[e] == ankle or below[bvh.end_parents[e]]
        ]
        if not pts:
            raise InputError(f"cannot map BVH joints: the {side} ankle has no foot below it", path)
        kind, idx, _ = max(pts, key=lambda t: float(np.linalg.norm(t[2] - rest_pos[0, ankle])))
        toe_point[side] = (kind, int(idx))
        heel = find("heel", side, below)
        heel_joint[side] = heel

    # spine: the joint between root and chest nearest half the pelvis→chest height (rest pose)
    path_joints = _ancestors(bvh.parents, chest)[1:-1]  # strictly between chest and root
    spine = -1
    if path_joints:
        pelvis_rest = 0.5 * (rest_pos[0, joint_of["l_hip"]] + rest_pos[0, joint_of["r_hip"]])
        mid = 0.5 * (pelvis_rest + rest_pos[0, chest])
        spine = min(path_joints, key=lambda k: float(np.linalg.norm(rest_pos[0, k] - mid)))
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


def load_bvh(
    path: str | os.PathLike[str],
    *,
    scale: float | None = None,
    stride: int = 1,
    max_frames: int | None = None,
) -> PoseSequence:
    """Read a BVH file as a `PoseSequence` in metres, Y up, facing +Z (rest pose), by the rules of this module.

    Parameters
    ----------
    scale : metres per file unit; default: picked from the rest-pose height (module docstring).
    stride : keep every `stride`-th frame.  max_frames : keep at most this many frames.

    InputError for unreadable files, and for skeletons whose names cannot be mapped (listing what is missing).
    """
    if stride < 1:
        raise InputError(f"stride must be at least 1, got {stride}", path)
    bvh = read_bvh(path)
    mapping = map_bvh_joints(bvh, path)
    frames = np.arange(0, bvh.n_frames, stride)
    if max_frames is not None:
        frames = frames[: max(0, int(max_frames))]
    if len(frames) == 0:
        raise InputError("no frames selected", path)
    rest_pos, rest_rot, rest_end = forward_kinematics(bvh, rest=True)
    pos, rot, end = forward_kinematics(bvh, frames)

    jo = mapping.joint_of
    ankles_rest = 0.5 * (rest_pos[0, jo["l_ankle"]] + rest_pos[0, jo["r_ankle"]])
    up_vec = rest_pos[0, mapping.head] - ankles_rest
    if not np.linalg.norm(up_vec) > 0:
        raise InputError("rest pose has the head at the ankles; cannot find the up axis", path)
    to_y = _rotation_to_y_up(up_vec)
    all_rest = np.concatenate([rest_pos[0], rest_end[0]]) @ to_y.T
    height_units = float(all_rest[:, 1].max() - all_rest[:, 1].min())
    if not height_units > 0:
        raise InputError("rest pose has no height", path)
    if scale is None:
        unit = min(UNITS, key=lambda u: abs(math.log(height_units * UNITS[u] / 1.7)))
        s = UNITS[unit]
    else:
        if not (scale > 0 and math.isfinite(scale)):
            raise InputError(f"scale must be a positive number of metres per unit, got {scale}", path)
        unit, s = "given", float(scale)
    # turn about Y so the rest pose's left hip is at +X (the person faces +Z)
    hip_axis = (rest_pos[0, jo["l_hip"]] - rest_pos[0, jo["r_hip"]]) @ to_y.T
    yaw = math.atan2(hip_axis[2], hip_axis[0])  # rotate by +yaw about Y takes (cos, ., sin) to +X
    c, sn = math.cos(yaw), math.sin(yaw)
    turn = np.array([[c, 0.0, sn], [0.0, 1.0, 0.0], [-sn, 0.0, c]])
    conv = s * (turn @ to_y)  # file units/axes -> metres, Y up, facing +Z

    out = np.empty((len(frames), len(JOINTS), 3))

    def put(name: str, xyz_file: np.ndarray) -> None:
        out[:, INDEX[name]] = xyz_file @ conv.T

    for name, j in jo.items():
        put(name, pos[:, j])
    put("pelvis", 0.5 * (pos[:, jo["l_hip"]] + pos[:, jo["r_hip"]]))
    put("chest", pos[:, mapping.chest])
    if mapping.spine >= 0:
        put("spine", pos[:, mapping.spine])
    else:
        put("spine", 0.5 * (0.5 * (pos[:, jo["l_hip"]] + pos[:, jo["r_hip"]]) + pos[:, mapping.chest]))
    # head centre: midpoint of the head joint and the highest rest point below it, fixed to the head's frame
    h = mapping.head
    below = _descendants(bvh.parents, h)
    cand = [rest_pos[0, k] for k in np.flatnonzero(below)]
    cand += [
        rest_end[0, e] for e in range(len(bvh.end_parents)) if bvh.end_parents[e] == h or below[bvh.end_parents[e]]
    ]
    if cand:
        top = max(cand, key=lambda p: float((p @ to_y.T)[1]))
        head_local = 0.5 * (top - rest_pos[0, h])  # rest rotations are identity: world offset = local offset
    else:
        head_local = np.zeros(3)
    put("head", pos[:, h] + np.einsum("nij,j->ni", rot[:, h], head_local))
    if mapping.neck >= 0:
        put("neck", pos[:, mapping.neck])
    else:
        put("neck", 0.5 * (pos[:, mapping.chest] + pos[:, h]))
    derived_feet: dict[str, bool] = {}
    for side in "lr":
        if f"{side}_clavicle" not in jo:
            # no collar bone: a point a fifth of the way from the neck base towards the shoulder
            put(f"{side}_clavicle", 0.8 * out_file_neck(pos, mapping) + 0.2 * pos[:, jo[f"{side}_shoulder"]])
        ankle = jo[f"{side}_ankle"]
        _, toe_derived, heel_local, toe_local = _foot_points(
            bvh, mapping, side, rest_pos, rest_end, to_y, turn, height_units
        )
        if toe_derived:
            put(f"{side}_toe", pos[:, ankle] + np.einsum("nij,j->ni", rot[:, ankle], toe_local))
        else:
            kind, idx = mapping.toe_point[side]
            put(f"{side}_toe", end[:, idx] if kind == "end" else pos[:, idx])
        if mapping.heel_joint[side] >= 0:
            put(f"{side}_heel", pos[:, mapping.heel_joint[side]])
        else:
            put(f"{side}_heel", pos[:, ankle] + np.einsum("nij,j->ni", rot[:, ankle], heel_local))
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
        "up_axis": _axis_name(up_vec),
        "yaw_deg": round(math.degrees(yaw), 3),
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


#: Anthropometric proportions of stature (Drillis & Contini): ankle height above the sole, heel behind the ankle,
#: toe tip in front of the ankle (foot length 0.152 minus the heel part).
ANKLE_HEIGHT = 0.039
HEEL_BACK = 0.03
TOE_FRONT = 0.12


def _foot_points(
    bvh: BvhFile,
    mapping: BvhMapping,
    side: str,
    rest_pos: np.ndarray,
    rest_end: np.ndarray,
    to_y: np.ndarray,
    turn: np.ndarray,
    height_units: float,
) -> tuple[np.ndarray, bool, np.ndarray, np.ndarray]:
    """Heel (and, for skeletons without a forward toe, toe) as points fixed to the ankle joint's frame.

    In the rest pose (all rotations identity, so world offsets are the ankle's local offsets) the heel lies
    ANKLE_HEIGHT·H below the ankle and HEEL_BACK·H behind it, "behind" being against the horizontal ankle→toe
    direction (H = rest height). When the farthest point below the ankle is not in front of it (less than 2 % of
    H horizontally, e.g. an End Site straight under the ankle) the toe is derived the same way, TOE_FRONT·H in
    front of the ankle along the facing direction (+Z after conversion), at the sole.
    Returns (toe point in file units at rest, toe derived?, heel local offset, toe local offset) in file axes.
    """
    ankle = mapping.joint_of[f"{side}_ankle"]
    kind, idx = mapping.toe_point[side]
    toe_rest = rest_end[0, idx] if kind == "end" else rest_pos[0, idx]
    a_y = rest_pos[0, ankle] @ to_y.T
    t_y = toe_rest @ to_y.T
    fwd = t_y - a_y
    fwd[1] = 0.0
    derived = float(np.linalg.norm(fwd)) < 0.02 * height_units
    if derived:
        fwd = turn.T @ np.array([0.0, 0.0, 1.0])  # facing direction (+Z after the turn), in Y-up axes
    fwd = fwd / np.linalg.norm(fwd)
    down = np.array([0.0, -ANKLE_HEIGHT * height_units, 0.0])
    heel_local = (down - HEEL_BACK * height_units * fwd) @ to_y  # Y-up axes back to file axes
    toe_local = (down + TOE_FRONT * height_units * fwd) @ to_y
    return toe_rest, derived, heel_local, toe_local


def out_file_neck(pos: np.ndarray, mapping: BvhMapping) -> np.ndarray:
    """(n, 3) file-frame position of the neck base as `load_bvh` defines it."""
    if mapping.neck >= 0:
        return pos[:, mapping.neck]
    return 0.5 * (pos[:, mapping.chest] + pos[:, mapping.head])
