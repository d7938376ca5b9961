"""PoseSequence and the kitsuke.poses v1 JSON file: exact round trip and validation of bad files."""

from __future__ import annotations

import json

import numpy as np
import pytest

from kitsuke.errors import InputError
from kitsuke.pose import PoseSequence, correct_poses, read_poses, write_poses
from kitsuke.skeleton import INDEX, JOINTS

from .test_correct import standing_pose


def _seq(n: int = 4) -> PoseSequence:
    rng = np.random.default_rng(0)
    pos = np.repeat(standing_pose()[None], n, axis=0) + rng.normal(0, 0.01, (n, len(JOINTS), 3))
    valid = np.ones(n, dtype=bool)
    valid[2] = False
    image = np.concatenate([rng.uniform(0, 500, (n, len(JOINTS), 2)), rng.uniform(0, 1, (n, len(JOINTS), 1))], -1)
    return PoseSequence(
        positions=pos,
        valid=valid,
        times=np.arange(n) / 30,
        fps=30.0,
        source={"kind": "video", "path": "clip.mp4", "size": [640, 480]},
        image=image,
    )


def test_round_trip_is_exact(tmp_path):
    seq = _seq()
    path = write_poses(seq, tmp_path / "p.json")
    back = read_poses(path)
    v = seq.valid
    assert np.array_equal(back.positions[v], seq.positions[v])  # bit-exact floats
    assert np.isnan(back.positions[~v]).all() and not back.valid[2]
    assert np.allclose(back.image[v, :, :2], seq.image[v, :, :2], atol=1e-3)
    assert back.fps == 30.0 and back.source["size"] == [640, 480] and back.joints == JOINTS
    doc = json.loads(path.read_text())
    assert doc["format"] == "kitsuke.poses" and doc["version"] == 1 and doc["up"] == [0, 1, 0]
    assert "positions" not in doc["frames"][2] and doc["frames"][2]["valid"] is False


def test_corrected_file_round_trip(tmp_path):
    seq = _seq()
    seq.positions[0, INDEX["r_knee"], 0] -= 0.5  # knees far apart in frame 0
    seq.positions[0, INDEX["r_ankle"], 0] -= 0.5
    c = correct_poses(seq)
    back = read_poses(write_poses(c.poses, tmp_path / "c.json"))
    assert back.corrected == c.poses.corrected and "r_knee" in back.corrected[0]
    assert np.array_equal(back.raw_positions[seq.valid], seq.positions[seq.valid])
    assert back.constraints.source == "calibrated"
    assert np.array_equal(back.constraints.knee.max_distance_m, c.poses.constraints.knee.max_distance_m)


def test_joint_order_in_file_is_respected(tmp_path):
    seq = _seq()
    doc = json.loads(write_poses(seq, tmp_path / "p.json").read_text())
    order = list(reversed(JOINTS))
    doc["joints"] = order
    for fr in doc["frames"]:
        if fr["valid"]:
            fr["positions"] = list(reversed(fr["positions"]))
            fr["image"] = list(reversed(fr["image"]))
    (tmp_path / "r.json").write_text(json.dumps(doc))
    back = read_poses(tmp_path / "r.json")
    assert np.array_equal(back.positions[seq.valid], seq.positions[seq.valid])


def _bad(tmp_path, edit) -> str:
    doc = json.loads(write_poses(_seq(), tmp_path / "ok.json").read_text())
    edit(doc)
    p = tmp_path / "bad.json"
    p.write_text(json.dumps(doc))
    return str(p)


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (lambda d: d["frames"][0]["positions"][3].__setitem__(1, float("nan")), "frame 0: positions has NaN"),
        (lambda d: d["frames"][1]["positions"].pop(), "frame 1: positions has 22 joints, expected 23"),
        (lambda d: d["joints"].remove("l_knee"), "missing joint(s) l_knee"),
        (lambda d: d["joints"].__setitem__(0, "hips"), "unknown joint name(s) 'hips'"),
        (lambda d: d["frames"][3].__setitem__("t", -1.0), "frame 3: t = -1.0 goes back in time"),
        (lambda d: d["frames"][0]["positions"][0].pop(), "frame 0: positions: joint pelvis needs a list of 3 numbers"),
        (lambda d: d.__setitem__("format", "other"), "not a kitsuke.poses file"),
        (lambda d: d.__setitem__("units", "cm"), 'units must be "m"'),
        (lambda d: d["frames"][0].pop("positions"), "frame 0: valid frame without positions"),
        (lambda d: d.__setitem__("fps", 0), "fps must be a positive number"),
    ],
)
def test_bad_files_raise_input_error_naming_file_and_problem(tmp_path, edit, message):
    path = _bad(tmp_path, edit)
    with pytest.raises(InputError) as e:
        read_poses(path)
    assert message in str(e.value)
    assert str(e.value).startswith(path)


def test_bad_file_via_cli_exit_2_one_line_no_output(tmp_path, run_cli):
    path = _bad(tmp_path, lambda d: d["frames"][0]["positions"][3].__setitem__(1, float("nan")))
    out = tmp_path / "out.json"
    r = run_cli("pose", "correct", path, "-o", out)
    assert r.code == 2
    assert r.err.count("\n") == 1 and "Traceback" not in r.err
    assert path in r.err and "NaN" in r.err
    assert not out.exists()


def test_not_json_and_empty(tmp_path):
    (tmp_path / "e.json").write_text("")
    (tmp_path / "t.json").write_text("{not json")
    with pytest.raises(InputError, match="empty"):
        read_poses(tmp_path / "e.json")
    with pytest.raises(InputError, match="invalid JSON"):
        read_poses(tmp_path / "t.json")


def test_dataclass_checks_shapes():
    with pytest.raises(ValueError):
        PoseSequence(positions=np.zeros((3, 23, 3)), valid=np.ones(2, bool), times=np.zeros(3), fps=30)
    with pytest.raises(ValueError, match="finite"):
        PoseSequence(positions=np.full((1, 23, 3), np.nan), valid=np.ones(1, bool), times=np.zeros(1), fps=30)
    s = PoseSequence(positions=np.zeros((2, 23, 3)), valid=np.array([True, False]), times=[0, 1], fps=1)
    assert np.isnan(s.positions[1]).all()  # invalid frames carry no positions
