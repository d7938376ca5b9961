"""The default body animated by a pose sequence: retargeting, the skin's quality, and the animated GLB (read back
here in numpy, and checked by the Khronos validator where it is installed)."""

from __future__ import annotations

import json
import struct
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from kitsuke.body import default_body
from kitsuke.body.animate import animate, posed_vertices, skinning_quality
from kitsuke.body.gltf_animation import animated_glb, write_animated_glb
from kitsuke.body.skinning import skin
from kitsuke.pose import PoseSequence, load_bvh
from kitsuke.skeleton import BONES, INDEX, JOINTS, PARENT_INDEX

from ..conftest import gltf_report, needs_gltf_validator

ROOT = Path(__file__).resolve().parent.parent.parent
KICK = ROOT / "tests" / "data" / "pose" / "cmu_10_01_soccer_kick_mh.bvh"


@pytest.fixture(scope="module")
def body():
    return default_body()


@pytest.fixture(scope="module")
def kick(body):
    poses = load_bvh(KICK, stride=2)
    return poses, animate(body, poses)


def _angle_deg(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    cos = (a * b).sum(-1) / (np.linalg.norm(a, axis=-1) * np.linalg.norm(b, axis=-1))
    return np.degrees(np.arccos(np.clip(cos, -1, 1)))


def test_limbs_point_where_the_performer_points_with_the_body_s_own_bones(body, kick):
    poses, anim = kick
    for a, b in [("l_hip", "l_knee"), ("l_knee", "l_ankle"), ("r_shoulder", "r_elbow"), ("r_elbow", "r_wrist")]:
        ia, ib = INDEX[a], INDEX[b]
        posed = anim.joints[:, ib] - anim.joints[:, ia]
        seen = poses.positions[:, ib] - poses.positions[:, ia]
        assert _angle_deg(posed, seen).max() < 0.5, (a, b)
    rest = body.rig.joints
    for a, b in BONES:
        length = np.linalg.norm(anim.joints[:, INDEX[b]] - anim.joints[:, INDEX[a]], axis=1)
        np.testing.assert_allclose(length, np.linalg.norm(rest[INDEX[b]] - rest[INDEX[a]]), atol=1e-9)
    # the feet stand on the floor: the lowest foot point over the clip is near y = 0
    feet = [INDEX[j] for j in ("l_heel", "l_toe", "r_heel", "r_toe", "l_ankle", "r_ankle")]
    assert -0.03 < np.percentile(anim.joints[:, feet, 1].min(axis=1), 5) < 0.08


def test_knees_bend_about_their_hinge(kick):
    """The thigh twists with the bend: the knee's hinge (the rest hinge carried by the thigh) stays across the
    leg's bend plane, so the shin swings in its plane instead of twisting the skin."""
    _, anim = kick
    j = anim.joints
    for side in "lr":
        hip, knee, ankle = (INDEX[f"{side}_{n}"] for n in ("hip", "knee", "ankle"))
        thigh, shin = j[:, knee] - j[:, hip], j[:, ankle] - j[:, knee]
        normal = np.cross(thigh, shin)
        bent = _angle_deg(thigh, shin) > 30
        assert bent.any()
        hinge = anim.rotations[:, hip] @ np.array([1.0, 0.0, 0.0])  # the knees' hinge is across the body at rest
        cos = np.abs((hinge * normal).sum(1)) / (np.linalg.norm(hinge, axis=1) * np.linalg.norm(normal, axis=1))
        assert np.median(cos[bent]) > 0.95


def test_skin_does_not_pinch_or_flip_at_knees_and_elbows(body, kick):
    _, anim = kick
    q = skinning_quality(body, anim)
    # measured 2026-11-26 on the kick: knees 0.25-1.18, elbows 0.69-1.50, no face turned; hips 0.22-1.90, 3 faces;
    # the whole body stretches one 7 mm edge at the collar 5.5-fold (four weights per vertex: the fourth changes
    # from the collar bone to the upper arm between two vertices there)
    for region in ("knees", "elbows"):
        assert q[region]["max_inverted_faces"] == 0, q[region]
        assert 0.2 < q[region]["min_edge_ratio"] and q[region]["max_edge_ratio"] < 1.6, q[region]
    assert q["hips"]["max_inverted_faces"] <= 5 and q["hips"]["min_edge_ratio"] > 0.15
    assert q["all"]["max_edge_ratio"] < 6.0


def test_frames_without_a_pose_hold_the_last_one(body, kick):
    poses, _ = kick
    valid = poses.valid.copy()
    valid[5:8] = False
    pos = poses.positions.copy()
    pos[5:8] = np.nan
    anim = animate(body, PoseSequence(pos, valid, poses.times, poses.fps))
    for f in (5, 6, 7):
        np.testing.assert_array_equal(anim.joints[f], anim.joints[4])


def test_bad_poses_are_refused(body, kick):
    from kitsuke.errors import InputError

    poses, _ = kick
    nobody = PoseSequence(np.full_like(poses.positions, np.nan), np.zeros(poses.n_frames, bool), poses.times, 30.0)
    with pytest.raises(InputError, match="no frame with a person"):
        animate(body, nobody)


# -- the GLB, read back -------------------------------------------------------------------------------------------
def _read_glb(data: bytes) -> tuple[dict, bytes]:
    magic, version, total = struct.unpack_from("<4sII", data, 0)
    assert magic == b"glTF" and version == 2 and total == len(data)
    n_json, kind = struct.unpack_from("<I4s", data, 12)
    assert kind == b"JSON"
    doc = json.loads(data[20 : 20 + n_json])
    n_bin, kind = struct.unpack_from("<I4s", data, 20 + n_json)
    assert kind == b"BIN\0"
    return doc, data[28 + n_json : 28 + n_json + n_bin]


def _accessor(doc: dict, binary: bytes, i: int) -> np.ndarray:
    acc = doc["accessors"][i]
    view = doc["bufferViews"][acc["bufferView"]]
    dtype = {5126: "<f4", 5123: "<u2", 5125: "<u4"}[acc["componentType"]]
    width = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT4": 16}[acc["type"]]
    a = np.frombuffer(binary, dtype, acc["count"] * width, view["byteOffset"])
    return a.reshape(acc["count"], width).astype(np.float64)


def test_glb_plays_back_the_same_skin(body, kick):
    """Evaluate the file as a viewer would (node tree, animation samples, skin with inverse bind matrices) and
    compare with the library's skinning: the same, to the file's float precision."""
    _, anim = kick
    doc, binary = _read_glb(animated_glb(body, anim))
    prim = doc["meshes"][0]["primitives"][0]
    rest = _accessor(doc, binary, prim["attributes"]["POSITION"])
    joints4 = _accessor(doc, binary, prim["attributes"]["JOINTS_0"]).astype(int)
    weights4 = _accessor(doc, binary, prim["attributes"]["WEIGHTS_0"])
    skin_doc = doc["skins"][0]
    ibm = _accessor(doc, binary, skin_doc["inverseBindMatrices"]).reshape(-1, 4, 4).transpose(0, 2, 1)
    node_of = {n: k for k, n in enumerate(skin_doc["joints"])}
    anim_doc = doc["animations"][0]
    frame = anim.n_frames // 2
    rot = {c["target"]["node"]: c["sampler"] for c in anim_doc["channels"] if c["target"]["path"] == "rotation"}
    trans = {c["target"]["node"]: c["sampler"] for c in anim_doc["channels"] if c["target"]["path"] == "translation"}
    times = _accessor(doc, binary, anim_doc["samplers"][0]["input"])[:, 0]
    assert len(times) == anim.n_frames
    glob = np.zeros((len(JOINTS), 4, 4))
    for j in range(len(JOINTS)):  # parents come first in JOINTS
        node = skin_doc["joints"][j]
        local = np.eye(4)
        q = _accessor(doc, binary, anim_doc["samplers"][rot[node]]["output"])[frame]
        local[:3, :3] = Rotation.from_quat(q).as_matrix()
        t = doc["nodes"][node]["translation"]
        if node in trans:
            t = _accessor(doc, binary, anim_doc["samplers"][trans[node]]["output"])[frame]
        local[:3, 3] = t
        p = PARENT_INDEX[j]
        glob[j] = local if p < 0 else glob[p] @ local
    assert node_of[skin_doc["joints"][0]] == 0
    mats = glob @ ibm  # (J, 4, 4) joint matrices
    blended = np.einsum("vk,vkab->vab", weights4, mats[joints4])
    played = np.einsum("vab,vb->va", blended[:, :3, :3], rest) + blended[:, :3, 3]
    w4 = np.zeros_like(anim.weights)
    np.put_along_axis(w4, joints4, weights4, axis=1)
    ours4 = skin(body.mesh.vertices, w4, body.rig.joints, anim.rotations[frame], anim.joints[frame])
    assert np.abs(played - ours4).max() < 1e-4  # float32 in the file
    assert np.abs(played - posed_vertices(body, anim, frame)).max() < 1e-4


@needs_gltf_validator
def test_glb_passes_the_khronos_validator(body, kick, tmp_path):
    _, anim = kick
    report = gltf_report(write_animated_glb(body, anim, tmp_path / "kick.glb"))
    assert report["errors"] == 0 and report["warnings"] == 0, report["messages"]


def test_cli_animate(tmp_path, run_cli):
    out = tmp_path / "kick.glb"
    r = run_cli("pose", "animate", KICK, "-o", out, "--stride", "4")
    assert r.code == 0, r.err
    summary = json.loads(r.out)
    assert summary["frames"] == 51 and summary["frames_posed"] == 51
    assert summary["skin"]["knees"]["max_inverted_faces"] == 0
    doc, _ = _read_glb(out.read_bytes())
    assert len(doc["animations"][0]["channels"]) == len(JOINTS) + 1 and doc["skins"][0]["joints"]
    r = run_cli("pose", "animate", KICK, "-o", tmp_path / "kick.obj")
    assert r.code == 2 and "output must end in .glb" in r.err
