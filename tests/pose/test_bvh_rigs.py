"""BVH files from rigs whose zero pose does not stand (issue 25): Character Creator / iClone legs folded up.

The two CMU clips are written again on a Character Creator style rig by tests/pose/_cc_rig.py (the same motion, the
bones' frames turned by 180°, ZYX channels, centimetres); `load_bvh` must read both files alike.
"""

from __future__ import annotations

import numpy as np
import pytest

from kitsuke.pose import forward_kinematics, load_bvh, parse_joint_name, read_bvh
from kitsuke.skeleton import INDEX

from ._cc_rig import cc_name, write_cc_rig
from .conftest import KICK, WALK

#: centimetres per file unit of the originals (inch; CMU's ASF unit 1/0.45 inch)
CM_PER_UNIT = {"kick": 2.54, "walk": 2.54 / 0.45}
CLIPS = {"kick": KICK, "walk": WALK}
Z_UP = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])  # +Y -> +Z
VARIANTS = {
    "legs": {},  # as Character Creator: legs folded, arms in a T-pose
    "spine": {"fold_spine": True},  # the whole zero pose upside down, left thigh on the right
    "z-up": {"fold_spine": True, "world": Z_UP},
}
CASES = [(c, v) for c in CLIPS for v in VARIANTS]
LEG_BONES = ("Thigh", "Calf", "Foot")


@pytest.fixture(scope="module")
def converted(tmp_path_factory):
    """(clip, variant) -> (path of the converted file, CcRig), written once."""
    out = {}
    folder = tmp_path_factory.mktemp("cc_rig")
    for clip, variant in CASES:
        path = folder / f"{clip}_{variant}.bvh"
        rig = write_cc_rig(CLIPS[clip], path, scale=CM_PER_UNIT[clip], **VARIANTS[variant])
        out[clip, variant] = (path, rig)
    return out


@pytest.fixture(scope="module")
def originals():
    return {clip: load_bvh(path) for clip, path in CLIPS.items()}


@pytest.mark.parametrize(("clip", "variant"), CASES)
def test_converter_keeps_the_motion(converted, clip, variant):
    """Forward kinematics of the converted file = the original's, scaled to cm (and turned Z up), within 1e-6."""
    path, rig = converted[clip, variant]
    orig, new = read_bvh(CLIPS[clip]), read_bvh(path)
    p0, _, e0 = forward_kinematics(orig)
    p1, _, e1 = forward_kinematics(new)
    i0 = [orig.names.index(v) for v in rig.original_of.values()]
    i1 = [new.names.index(k) for k in rig.original_of]
    assert len(i0) >= 19  # every mapped joint of the original has its converted twin
    expect = rig.scale * p0[:, i0] @ rig.world.T
    assert np.abs(p1[:, i1] - expect).max() <= 1e-6 * np.abs(expect).max()
    # the End Sites too (the converted file has one more on each twist helper)
    twin = [rig.original_of.get(new.names[j]) for j in new.end_parents]
    ends1 = [k for k, name in enumerate(twin) if name is not None]
    ends0 = [
        k
        for name in dict.fromkeys(n for n in twin if n)
        for k in np.flatnonzero(orig.end_parents == orig.names.index(name))
    ]
    assert len(ends0) == len(ends1) == len(orig.end_parents)
    expect = rig.scale * e0[:, ends0] @ rig.world.T
    assert np.abs(e1[:, ends1] - expect).max() <= 1e-6 * np.abs(expect).max()
    # it is the rig of the issue: CC names, ZYX channels, legs pointing up in the zero pose
    assert new.names[0] == "CC_Base_Hip" and "CC_Base_Pelvis" in new.names and "CC_Base_L_ThighTwist01" in new.names
    assert all(ch[-3:] == ("Zrotation", "Yrotation", "Xrotation") for ch in new.channels)
    up = rig.world @ [0.0, 1.0, 0.0]
    calf = new.names.index("CC_Base_L_Calf")
    off = new.offsets[calf]  # cm, up the leg (Character Creator: (-0.2, 47.7, -0.3))
    assert off @ up > 0.9 * np.linalg.norm(off) > 35.0
    assert 90.0 < np.median(new.motion[:, :3] @ up) < 110.0  # the root about a metre up, in cm
    rest, _, _ = forward_kinematics(new, rest=True)
    head, ankles = rest[0, new.names.index("CC_Base_Head")], rest[0, new.names.index("CC_Base_L_Foot")]
    assert (head - ankles) @ up < 0  # the zero pose has the feet above the head: read from it, the clip is upside down


@pytest.mark.parametrize(
    ("name", "side", "base"),
    [
        ("CC_Base_Hip", None, "hip"),
        ("CC_Base_Pelvis", None, "pelvis"),
        ("CC_Base_Waist", None, "waist"),
        ("CC_Base_Spine01", None, "spine"),
        ("CC_Base_Spine02", None, "spine"),
        ("CC_Base_NeckTwist01", None, "neck"),
        ("CC_Base_Head", None, "head"),
        ("CC_Base_L_Thigh", "l", "thigh"),
        ("CC_Base_R_Calf", "r", "calf"),
        ("CC_Base_L_Foot", "l", "foot"),
        ("CC_Base_L_ToeBase", "l", "toebase"),
        ("CC_Base_L_Clavicle", "l", "clavicle"),
        ("CC_Base_R_Upperarm", "r", "upperarm"),
        ("CC_Base_L_Forearm", "l", "forearm"),
        ("CC_Base_L_Hand", "l", "hand"),
        ("CC_Base_L_ThighTwist01", "l", "thigh"),  # a helper below the thigh: the thigh is nearer the root
    ],
)
def test_character_creator_names(name, side, base):
    assert parse_joint_name(name) == (side, base)


@pytest.mark.parametrize(("clip", "variant"), CASES)
def test_character_creator_rig_reads_like_the_original(converted, originals, clip, variant):
    path, _ = converted[clip, variant]
    a, b = originals[clip], load_bvh(path)
    assert b.n_frames == a.n_frames and b.fps == a.fps
    dist_mm = 1000 * np.linalg.norm(b.positions - a.positions, axis=2)
    assert dist_mm.max() < 1.0, f"{dist_mm.max():.3g} mm"
    assert b.source["up_axis"] == ("+Z" if variant == "z-up" else "+Y") and b.source["up_from"] == "motion"
    assert b.source["yaw_deg"] == a.source["yaw_deg"] == 0.0
    assert b.source["units"] == "cm" and abs(b.source["rest_height_m"] - a.source["rest_height_m"]) < 1e-3
    assert b.source["height_from"] == "reference pose"
    # the folded legs were recognised as such; the pelvis is mid-hips, not CC_Base_Pelvis
    unfolded = set(b.source["unfolded_joints"])
    assert {f"CC_Base_{s}_{bone}" for s in "LR" for bone in LEG_BONES} <= unfolded and "CC_Base_Hip" not in unfolded
    names = read_bvh(CLIPS[clip]).names

    def renamed(rule: str) -> str:
        return " ".join(cc_name(w, names) if w in names else w for w in rule.split())

    assert b.source["joint_map"] == {k: renamed(v) for k, v in a.source["joint_map"].items()}
    assert b.source["joint_map"]["l_hip"] == "CC_Base_L_Thigh" and b.source["joint_map"]["pelvis"] == "mid-hips"
    # upright in every frame
    p = b.positions
    assert (p[:, INDEX["head"], 1] > p[:, INDEX["pelvis"], 1] + 0.3).all()
    assert (p[:, INDEX["pelvis"], 1] > np.minimum(p[:, INDEX["l_ankle"], 1], p[:, INDEX["r_ankle"], 1])).all()


def test_character_creator_mapping_names(converted):
    m = load_bvh(converted["walk", "legs"][0]).source["joint_map"]
    expected = {
        "l_hip": "CC_Base_L_Thigh",
        "l_knee": "CC_Base_L_Calf",
        "l_ankle": "CC_Base_L_Foot",
        "l_toe": "end of CC_Base_L_ToeBase",
        "r_shoulder": "CC_Base_R_Upperarm",
        "r_elbow": "CC_Base_R_Forearm",
        "r_wrist": "CC_Base_R_Hand",
        "l_clavicle": "CC_Base_L_Clavicle",
        "chest": "CC_Base_Spine02",
        "neck": "CC_Base_NeckTwist01",
        "head": "centre of CC_Base_Head",
    }
    assert {k: m[k] for k in expected} == expected


def test_rest_height_and_facing(converted):
    kick = load_bvh(converted["kick", "spine"][0])
    assert 1.5 < kick.source["rest_height_m"] < 1.8  # the known stature of the MakeHuman-sized kick (1.63 m)
    foot = kick.joint("l_toe") - kick.joint("l_heel")
    assert foot[0, 2] > 0.1 and (kick.joint("l_hip") - kick.joint("r_hip"))[0, 0] > 0.1  # toes forward, left at +X
    # the walk comes out facing where it walks: forward (+Z), left at +X
    walk = load_bvh(converted["walk", "z-up"][0])
    travel = walk.joint("pelvis")[-1] - walk.joint("pelvis")[0]
    assert travel[2] > 2.0 and abs(travel[0]) < 0.3 * travel[2]
    hips = walk.joint("l_hip") - walk.joint("r_hip")
    assert np.median(hips[:, 0]) > 0.1


def test_axes_are_decided_on_the_whole_clip(converted):
    """A part of the clip is read in the same axes, units and reference pose as the whole."""
    path = converted["walk", "spine"][0]
    whole = load_bvh(path)
    part = load_bvh(path, stride=4, max_frames=50)
    assert np.array_equal(part.positions, whole.positions[::4][:50])
    assert part.source["rest_height_m"] == whole.source["rest_height_m"]
