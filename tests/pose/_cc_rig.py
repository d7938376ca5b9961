"""Test-only: write a BVH clip again on a Character Creator / iClone style rig that describes the same motion.

Such rigs (issue 25) name their joints `CC_Base_*`, write ZYX channels, centimetres, and give some bones a bind
frame turned by 180°: in the zero pose (all channels zero) the legs' offsets point *up*, and every frame's rotations
carry the 180° that folds them back down. `cc_rig_bvh` builds that from any parsed clip:

- every joint j of the new rig moves with a joint a(j) of the original ("anchor") with its frame turned by a fixed
  `bind` rotation: world rotation W'_j = Q·W_a(j)·B_j·Qᵀ and position P'_j = s·Q·(P_a(j) + W_a(j)·c_j) (Q: a whole-
  clip rotation, e.g. to Z up; s: units to centimetres; c_j: a point fixed to the anchor, zero except for the twist
  bones, which sit half way along their bone);
- its local rotation is W'_parentᵀ·W'_j (written as Z, Y, X Euler angles with scipy) and its offset is
  W'_parentᵀ·(P'_j − P'_parent), which the construction makes constant over the clip (checked);
- joints whose motion is constant may be dropped (CMU's `LHipJoint`, `lhand`: the rig has no such helper), a
  `CC_Base_Pelvis` holding the legs and a `CC_Base_Waist` holding the spine are inserted when the clip has none.

So forward kinematics of the new file gives s·Q times the original's positions, to the printed precision.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from kitsuke.pose import BvhFile, forward_kinematics, read_bvh

#: CMU joint names (both the ASF-style walk and the MakeHuman-style kick) -> Character Creator names, left side;
#: the right side mirrors (Left -> R_). Names not listed keep theirs behind the `CC_Base_` prefix.
CC_NAMES = {
    "Hips": "Hip",
    "LeftHip": "L_Thigh",
    "LeftKnee": "L_Calf",
    "LeftAnkle": "L_Foot",
    "LeftToe": "L_ToeBase",
    "lowerback": "Waist",
    "Chest": "Spine01",
    "Chest2": "Spine02",
    "CS_BVH": "Spine02",
    "lowerneck": "NeckTwist01",
    "Head": "Head",
    "LeftCollar": "L_Clavicle",
    "LeftShoulder": "L_Upperarm",
    "LeftElbow": "L_Forearm",
    "LeftWrist": "L_Hand",
    "LFingers": "L_Mid1",
    "LThumb": "L_Thumb1",
}
#: Joints with constant motion that the Character Creator rig does not have.
DROPPED = ("LHipJoint", "RHipJoint", "lhand", "rhand")
#: Bones that get a twist helper (a leaf `…Twist01` half way along them, as the real rig has).
TWISTED = ("Thigh", "Calf", "Upperarm", "Forearm")

LEG = ("Thigh", "Calf", "Foot", "ToeBase")
SPINE = ("Waist", "Spine01", "Spine02", "NeckTwist01", "NeckTwist02", "Head")
ARM = ("Upperarm", "Forearm", "Hand", "Mid1", "Thumb1")


def _rot(axis: str, deg: float) -> np.ndarray:
    """(3, 3) rotation about a coordinate axis."""
    return Rotation.from_euler(axis, deg, degrees=True).as_matrix()


def cc_name(name: str, names: list[str]) -> str:
    """The Character Creator name of a CMU joint (`names`: all the clip's joints, for the neck's numbering)."""
    if name == "Neck":  # the first neck joint is NeckTwist01; the walk has a `lowerneck` below `Neck`
        return "CC_Base_NeckTwist02" if "lowerneck" in names else "CC_Base_NeckTwist01"
    for cmu, side in (("Left", "L"), ("Right", "R"), ("L", "L"), ("R", "R")):
        if name.startswith(cmu) and name[len(cmu) :][:1].isupper():
            left = CC_NAMES.get("Left" + name[len(cmu) :]) or CC_NAMES.get("L" + name[len(cmu) :])
            if left:
                return "CC_Base_" + side + left[1:]
    return "CC_Base_" + CC_NAMES.get(name, name)


def bind_rotation(cc: str, fold_spine: bool) -> np.ndarray:
    """(3, 3) the fixed turn of a joint's frame on the new rig (B_j, applied on the right of its world rotation).

    Legs: 180° about Z, so their offsets point up the leg in the zero pose (as CC's calf, (-0.2, 47.7, -0.3) cm).
    Arms: 90° about Z, a T-pose in the zero pose. With `fold_spine` also the spine and head (180° about X: the zero
    pose hangs head down) and the pelvis (180° about Y: the zero pose has the left thigh on the right).
    """
    base = cc.removeprefix("CC_Base_")
    side = base[0] if base[:2] in ("L_", "R_") else ""
    word = base[2:] if side else base
    word = word.removesuffix("Twist01") if word.endswith("Twist01") and word != "NeckTwist01" else word
    if word in LEG:
        return _rot("z", 180.0)
    if word in ARM:
        return _rot("z", -90.0 if side == "L" else 90.0)
    if fold_spine and word in SPINE:
        return _rot("x", 180.0)
    if fold_spine and word == "Pelvis":
        return _rot("y", 180.0)
    return np.eye(3)


@dataclass
class _NewJoint:
    name: str
    parent: int  # index in the new rig, -1 for the root
    anchor: int  # the original joint it moves with
    bind: np.ndarray  # (3, 3)
    point: np.ndarray = field(default_factory=lambda: np.zeros(3))  # (3,) fixed to the anchor, original units
    ends: list[int] = field(default_factory=list)  # the original End Sites it carries


@dataclass
class CcRig:
    """A converted clip: the BVH text, and which new joint stands on which original joint (by name)."""

    text: str
    original_of: dict[str, str]
    scale: float
    world: np.ndarray


def _children(bvh: BvhFile) -> list[list[int]]:
    kids: list[list[int]] = [[] for _ in bvh.names]
    for j, p in enumerate(bvh.parents):
        if p >= 0:
            kids[p].append(j)
    return kids


def _build(bvh: BvhFile, fold_spine: bool) -> list[_NewJoint]:
    """The new rig's joints in file order (parents first): renamed, helpers dropped, pelvis/waist/twists added."""
    kids = _children(bvh)
    names = bvh.names
    new: list[_NewJoint] = []

    def add(name: str, parent: int, anchor: int, point: np.ndarray | None = None) -> int:
        new.append(_NewJoint(name, parent, anchor, bind_rotation(name, fold_spine)))
        if point is not None:
            new[-1].point = point
        return len(new) - 1

    def legs_below(j: int) -> bool:
        return cc_name(names[j], names).endswith("_Thigh") or any(legs_below(k) for k in kids[j])

    def emit(j: int, parent: int) -> None:
        if names[j] in DROPPED:
            assert not (bvh.end_parents == j).any(), f"{names[j]} carries an End Site"
            for k in kids[j]:
                emit(k, parent)
            return
        me = add(cc_name(names[j], names), parent, j)
        new[me].ends = [e for e in range(len(bvh.end_parents)) if bvh.end_parents[e] == j]
        if new[me].name.removeprefix("CC_Base_")[2:] in TWISTED and kids[j]:
            # listed first, so that the role search meets the helper before the real chain
            add(new[me].name + "Twist01", me, j, 0.5 * bvh.offsets[kids[j][0]])
        for k in kids[j]:
            emit(k, me)

    root = add(cc_name(names[0], names), -1, 0)
    pelvis = add("CC_Base_Pelvis", root, 0)
    has_waist = any(cc_name(n, names) == "CC_Base_Waist" for n in names)
    waist = root if has_waist else add("CC_Base_Waist", root, 0)
    for k in kids[0]:
        emit(k, pelvis if legs_below(k) else waist)
    return new


def _world(
    bvh: BvhFile, new: list[_NewJoint], scale: float, world: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per new joint, world rotations (n, J', 3, 3) and positions (n, J', 3) in the new file's units and axes, and
    the End Sites' positions (n, E, 3)."""
    pos, rot, end = forward_kinematics(bvh)
    anchors = np.array([j.anchor for j in new])
    binds = np.array([j.bind for j in new])
    points = np.array([j.point for j in new])
    w_new = world @ rot[:, anchors] @ binds @ world.T
    p_new = scale * (pos[:, anchors] + np.einsum("njab,jb->nja", rot[:, anchors], points)) @ world.T
    return w_new, p_new, scale * end @ world.T


def cc_rig_bvh(bvh: BvhFile, *, scale: float = 1.0, world: np.ndarray | None = None, fold_spine: bool = False) -> CcRig:
    """Write `bvh`'s motion on a Character Creator style rig (module docstring).

    scale : new units per original unit (to centimetres: 2.54 for inches).  world : (3, 3) rotation of the whole
    clip (default none; `Rx(90°)` makes it Z up).  fold_spine : fold the spine, head and pelvis too.
    """
    world = np.eye(3) if world is None else np.asarray(world, dtype=float)
    new = _build(bvh, fold_spine)
    w_new, p_new, e_new = _world(bvh, new, scale, world)
    n = len(bvh.motion)
    offsets, locals_ = [], []
    for j, nj in enumerate(new):
        if nj.parent < 0:
            offsets.append(p_new[0, j])
            locals_.append(w_new[:, j])
            continue
        wp = w_new[:, nj.parent]
        off = np.einsum("nba,nb->na", wp, p_new[:, j] - p_new[:, nj.parent])  # parent's frame
        spread = np.ptp(off, axis=0).max()
        if spread > 1e-6 * scale * (1.0 + np.abs(off).max()):
            raise ValueError(f"{nj.name}: its offset moves by {spread:.3g} over the clip (a dropped joint moves?)")
        offsets.append(off.mean(axis=0))
        locals_.append(np.einsum("nba,nbc->nac", wp, w_new[:, j]))
    end_offsets = {
        e: np.einsum("ba,b->a", w_new[0, j], e_new[0, e] - p_new[0, j]) for j, nj in enumerate(new) for e in nj.ends
    }

    kids: list[list[int]] = [[] for _ in new]
    for j, nj in enumerate(new):
        if nj.parent >= 0:
            kids[nj.parent].append(j)
    lines = ["HIERARCHY"]
    order: list[int] = []  # joints in the order the file lists them (depth first): the motion's column order

    def write(j: int, depth: int) -> None:
        pad = "  " * depth
        nj = new[j]
        order.append(j)
        lines.append(f"{pad}{'ROOT' if nj.parent < 0 else 'JOINT'} {nj.name}")
        lines.append(f"{pad}{{")
        lines.append(f"{pad}  OFFSET {' '.join(f'{v:.9f}' for v in offsets[j])}")
        chans = "Zrotation Yrotation Xrotation"
        lines.append(
            f"{pad}  CHANNELS 6 Xposition Yposition Zposition {chans}"
            if nj.parent < 0
            else f"{pad}  CHANNELS 3 {chans}"
        )
        for k in kids[j]:
            write(k, depth + 1)
        site_offsets = [end_offsets[e] for e in nj.ends]
        if not kids[j] and not site_offsets:
            site_offsets = [scale * np.array([0.0, 1.0, 0.0])]  # a leaf (twist helper) still ends in a site
        for off in site_offsets:
            xyz = " ".join(f"{v:.9f}" for v in off)
            lines.extend([f"{pad}  End Site", f"{pad}  {{", f"{pad}    OFFSET {xyz}", f"{pad}  }}"])
        lines.append(f"{pad}}}")

    write(0, 0)
    # ZYX channels: R = Rz·Ry·Rx, which is scipy's intrinsic "ZYX"
    euler = [Rotation.from_matrix(locals_[j]).as_euler("ZYX", degrees=True) for j in order]
    motion = np.concatenate([p_new[:, 0], *euler], axis=1)
    lines += ["MOTION", f"Frames: {n}", f"Frame Time: {bvh.frame_time!r}"]
    lines += [" ".join(f"{v:.9f}" for v in row) for row in motion]
    # the joints that stand on an original joint (not the inserted pelvis and waist, nor the twist helpers)
    original_of = {nj.name: bvh.names[nj.anchor] for nj in new if cc_name(bvh.names[nj.anchor], bvh.names) == nj.name}
    return CcRig("\n".join(lines) + "\n", original_of, scale, world)


def write_cc_rig(src: Path, dst: Path, **kwargs) -> CcRig:
    """Read the BVH file `src`, write it on a Character Creator style rig to `dst` (keywords of `cc_rig_bvh`)."""
    rig = cc_rig_bvh(read_bvh(src), **kwargs)
    dst.write_text(rig.text)
    return rig
