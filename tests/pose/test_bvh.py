"""BVH: parser, forward kinematics, naming rules (CMU, MakeHuman, DAZ, Mixamo), units and axes, bad files."""

from __future__ import annotations

import re

import numpy as np
import pytest

from kitsuke.errors import InputError
from kitsuke.pose import forward_kinematics, load_bvh, parse_joint_name, read_bvh
from kitsuke.skeleton import INDEX

from .conftest import KICK, MH_STANDING, WALK


@pytest.mark.parametrize(
    ("name", "side", "base"),
    [
        ("LeftUpLeg", "l", "upleg"),
        ("mixamorig:RightForeArm", "r", "forearm"),
        ("upperleg01.L", "l", "upperleg"),
        ("lowerleg02.R", "r", "lowerleg"),
        ("lThighBend", "l", "thigh"),
        ("rShldrBend", "r", "shldr"),
        ("lCollar", "l", "collar"),
        ("LHipJoint", "l", "hipjoint"),
        ("lowerback", None, "lowerback"),
        ("lhand", "l", "hand"),
        ("Bip01 L Thigh", "l", "thigh"),
        ("RightShoulder", "r", "shoulder"),
        ("CS_BVH", None, "csbvh"),
        ("l_knee", "l", "knee"),
        ("neckLower", None, "necklower"),
        ("Head", None, "head"),
        ("foot_R", "r", "foot"),
        ("HandLeft", "l", "hand"),
    ],
)
def test_name_rules(name, side, base):
    assert parse_joint_name(name) == (side, base)


#: Bones that are BVH bones in every mapping (a joint and its mapped descendant joint): rigid under FK. Others
#: (pelvis = mid-hips → spine, neck → head centre, ankle → toe tip across a toe joint) may bend with the motion.
RIGID = [
    (f"{s}_{a}", f"{s}_{b}")
    for s in "lr"
    for a, b in (("hip", "knee"), ("knee", "ankle"), ("ankle", "heel"), ("shoulder", "elbow"), ("elbow", "wrist"))
]


def _bone_lengths(poses) -> np.ndarray:
    """(n, bones) lengths of the RIGID bones."""
    b = np.array([[INDEX[a], INDEX[c]] for a, c in RIGID])
    return np.linalg.norm(poses.positions[:, b[:, 1]] - poses.positions[:, b[:, 0]], axis=2)


def test_cmu_kick_on_makehuman_skeleton(kick):
    m = kick.source["joint_map"]
    assert m["l_hip"] == "LeftHip" and m["r_knee"] == "RightKnee" and m["l_ankle"] == "LeftAnkle"
    assert m["l_shoulder"] == "LeftShoulder" and m["l_clavicle"] == "LeftCollar"
    assert m["chest"] == "CS_BVH" and m["spine"] == "Chest" and m["neck"] == "Neck"
    assert m["l_toe"].startswith("derived")  # its ankles end in a site straight below: no toe
    assert kick.source["units"] == "inch" and 1.5 < kick.source["rest_height_m"] < 1.8
    assert kick.n_frames == 201 and kick.fps == 30
    # the known fact of this clip: the right thigh reaches about 87° from vertical
    thigh = kick.joint("r_knee") - kick.joint("r_hip")
    ang = np.degrees(np.arccos(-thigh[:, 1] / np.linalg.norm(thigh, axis=1)))
    assert 80 < ang.max() < 95
    # rigid skeleton: bone lengths constant over the clip (FK), feet forward (+Z), left at +X
    lengths = _bone_lengths(kick)
    assert np.ptp(lengths, axis=0).max() < 1e-9
    foot = kick.joint("l_toe") - kick.joint("l_heel")
    assert foot[0, 2] > 0.1 and (kick.joint("l_hip") - kick.joint("r_hip"))[0, 0] > 0.1


def test_cmu_walk_asf_names_and_units(walk):
    m = walk.source["joint_map"]
    assert m["l_hip"] == "LeftHip" and m["l_clavicle"] == "LeftCollar" and m["l_shoulder"] == "LeftShoulder"
    assert m["l_wrist"] == "LeftWrist" and m["chest"] == "Chest2" and m["neck"] == "lowerneck"
    assert m["l_toe"] == "end of LeftToe"
    assert walk.source["units"] == "cmu" and walk.fps == 120 and walk.n_frames == 994
    assert np.ptp(_bone_lengths(walk), axis=0).max() < 1e-9
    # the floor: feet touch y≈0 in stance (CMU's ground plane), the head ~1.3–1.5 m up
    assert abs(np.percentile(walk.joint("r_toe")[:, 1], 2)) < 0.05
    assert 1.2 < np.median(walk.joint("head")[:, 1]) < 1.6
    # it walks: the pelvis travels more than 2 m
    assert np.linalg.norm(walk.joint("pelvis")[-1, ::2] - walk.joint("pelvis")[0, ::2]) > 2.0


def test_makehuman_z_up_decimetres():
    s = load_bvh(MH_STANDING)
    m = s.source["joint_map"]
    assert m["l_hip"] == "upperleg01.L" and m["l_knee"] == "lowerleg01.L" and m["l_ankle"] == "foot.L"
    assert m["l_shoulder"] == "upperarm01.L" and m["l_clavicle"] == "clavicle.L" and m["l_wrist"] == "wrist.L"
    assert s.source["up_axis"] == "+Z" and s.source["units"] == "dm"
    p = s.positions[0]
    assert p[INDEX["head"], 1] - p[INDEX["l_ankle"], 1] > 1.3  # Y up after conversion
    assert p[INDEX["l_hip"], 0] > p[INDEX["r_hip"], 0]  # left at +X
    assert p[INDEX["l_toe"], 2] > p[INDEX["l_heel"], 2]  # feet forward (+Z)


def _renamed(tmp_path, mapping: dict[str, str], name: str) -> str:
    text = KICK.read_text()
    for old, new in mapping.items():
        text = re.sub(rf"\b(JOINT|ROOT) {old}\b", rf"\1 {new}", text)
    p = tmp_path / name
    p.write_text(text)
    return str(p)


MIXAMO = {
    "Hips": "mixamorig:Hips",
    "LeftHip": "mixamorig:LeftUpLeg",
    "LeftKnee": "mixamorig:LeftLeg",
    "LeftAnkle": "mixamorig:LeftFoot",
    "RightHip": "mixamorig:RightUpLeg",
    "RightKnee": "mixamorig:RightLeg",
    "RightAnkle": "mixamorig:RightFoot",
    "Chest": "mixamorig:Spine",
    "CS_BVH": "mixamorig:Spine2",
    "LeftCollar": "mixamorig:LeftShoulder",
    "LeftShoulder": "mixamorig:LeftArm",
    "LeftElbow": "mixamorig:LeftForeArm",
    "LeftWrist": "mixamorig:LeftHand",
    "RightCollar": "mixamorig:RightShoulder",
    "RightShoulder": "mixamorig:RightArm",
    "RightElbow": "mixamorig:RightForeArm",
    "RightWrist": "mixamorig:RightHand",
    "Neck": "mixamorig:Neck",
    "Head": "mixamorig:Head",
}
DAZ = {
    "Hips": "hip",
    "LeftHip": "lThigh",
    "LeftKnee": "lShin",
    "LeftAnkle": "lFoot",
    "RightHip": "rThighBend",
    "RightKnee": "rShin",
    "RightAnkle": "rFoot",
    "Chest": "abdomen",
    "CS_BVH": "chest",
    "LeftCollar": "lCollar",
    "LeftShoulder": "lShldr",
    "LeftElbow": "lForeArm",
    "LeftWrist": "lHand",
    "RightCollar": "rCollar",
    "RightShoulder": "rShldrBend",
    "RightElbow": "rForearmBend",
    "RightWrist": "rHand",
    "Neck": "neck",
    "Head": "head",
}


@pytest.mark.parametrize(("names", "label"), [(MIXAMO, "mixamo"), (DAZ, "daz")])
def test_other_naming_conventions_give_the_same_poses(tmp_path, kick, names, label):
    s = load_bvh(_renamed(tmp_path, names, f"{label}.bvh"))
    assert np.array_equal(s.positions, kick.positions)
    assert s.source["joint_map"]["l_clavicle"] == names["LeftCollar"]


def test_unmappable_bvh_lists_what_is_missing(tmp_path, run_cli):
    path = _renamed(tmp_path, {"LeftKnee": "Bone07", "RightWrist": "Bone12", "Head": "Bone13"}, "odd.bvh")
    with pytest.raises(InputError) as e:
        load_bvh(path)
    msg = str(e.value)
    assert msg.startswith(path) and "l_knee" in msg and "r_wrist" in msg and "head" in msg and "Bone07" in msg
    assert "l_ankle" in msg  # searched below the knee, which is missing
    out = tmp_path / "o.json"
    r = run_cli("pose", "extract", path, "-o", out)
    assert r.code == 2 and "l_knee" in r.err and r.err.count("\n") == 1 and not out.exists()


def test_rotation_orders_and_channels(tmp_path):
    """A two-joint chain with known answers: R = product of the channels in file order."""
    text = """HIERARCHY
ROOT a
{
  OFFSET 0 0 0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
  JOINT b
  {
    OFFSET 0 1 0
    CHANNELS 3 Xrotation Yrotation Zrotation
    End Site
    {
      OFFSET 0 1 0
    }
  }
}
MOTION
Frames: 2
Frame Time: 0.5
1 2 3 90 0 0 0 0 0
0 0 0 90 90 0 0 0 90
"""
    (tmp_path / "t.bvh").write_text(text)
    b = read_bvh(tmp_path / "t.bvh")
    assert b.fps == 2 and b.channels[0][3:] == ("Zrotation", "Xrotation", "Yrotation")
    pos, rot, end = forward_kinematics(b)
    # frame 0: root at (1,2,3) turned 90° about Z: its +Y offset points to -X
    assert np.allclose(pos[0, 1], [1 - 1, 2, 3], atol=1e-12) and np.allclose(end[0, 0], [-1, 2, 3], atol=1e-12)
    # frame 1: root Rz(90)·Rx(90); joint b adds Rz(90): end site = b + Rz90·Rx90·Rz90·(0,1,0)
    rz = np.array([[0, -1, 0], [1, 0, 0], [0, 0, 1.0]])
    rx = np.array([[1, 0, 0], [0, 0, -1], [0, 1, 0.0]])
    assert np.allclose(pos[1, 1], rz @ rx @ [0, 1, 0], atol=1e-12)
    assert np.allclose(end[1, 0], pos[1, 1] + rz @ rx @ rz @ [0, 1, 0], atol=1e-12)


@pytest.mark.parametrize(
    ("cut", "message"),
    [
        (lambda t: t[: len(t) // 2], "truncated MOTION data"),
        (lambda t: t[: t.index("MOTION") - 40], "not a BVH file"),
        (lambda t: re.sub(r"Frames:\s*201", "Frames: 0", t), "no frames"),
        (lambda t: t.replace("OFFSET", "OFSET", 1), "unexpected 'OFSET'"),
        (lambda t: "hello", "not a BVH file"),
    ],
)
def test_bad_bvh_files(tmp_path, cut, message):
    (tmp_path / "b.bvh").write_text(cut(KICK.read_text()))
    with pytest.raises(InputError, match=message):
        load_bvh(tmp_path / "b.bvh")


def test_nan_in_motion(tmp_path):
    lines = KICK.read_text().splitlines()
    lines[-3] = " ".join(["nan"] + lines[-3].split()[1:])
    (tmp_path / "n.bvh").write_text("\n".join(lines) + "\n")
    with pytest.raises(InputError, match="NaN"):
        load_bvh(tmp_path / "n.bvh")


def test_stride_scale_and_subset():
    s = load_bvh(WALK, stride=4, max_frames=50, scale=0.05)
    assert s.n_frames == 50 and s.fps == 30 and s.source["units"] == "given"
    assert np.allclose(np.diff(s.times), 4 / 120)
