"""Drags files (SPEC §3.5) and `kitsuke drag`: replay on a dressed-garment OBJ; bad files fail cleanly."""

from __future__ import annotations

import json

import numpy as np
import pytest

from kitsuke.cloth import BodyCollider
from kitsuke.dressing.drag import DragSession
from kitsuke.dressing.drags import Drags, DragStep, apply_drags, drags_from_dict, read_drags, write_drags
from kitsuke.dressing.export import read_garment_obj, write_garment_obj
from kitsuke.errors import InputError

from .test_drag import front_of, skirt_garment


@pytest.fixture(scope="module")
def collider(body):
    return BodyCollider.from_body(body)


@pytest.fixture(scope="module")
def skirt_obj(body, tmp_path_factory):
    garment, _ = skirt_garment(body)
    path = tmp_path_factory.mktemp("drag") / "skirt.obj"
    write_garment_obj(garment, path)
    return path


@pytest.fixture
def cli(run_cli):
    """`kitsuke drag ...` in-process."""
    return run_cli


def lift_file(garment_positions: np.ndarray, body_surface) -> dict:
    """Pin the back of the skirt, grab its front, move the grab 4 cm up in two points; then unpin all."""
    x = garment_positions
    g = front_of(x, 0.9)
    back = int(np.argmin(x[:, 2] + 5 * np.abs(x[:, 1] - 0.9) + 5 * np.abs(x[:, 0])))
    foot = body_surface.closest(x[g]).points[0]
    path = [foot + [0, 0.02, 0], foot + [0, 0.04, 0]]
    return {
        "format": "kitsuke.drags",
        "version": 1,
        "steps": [
            {"pins": [x[back].tolist()], "grab": x[g].tolist(), "path": [p.tolist() for p in path]},
            {"unpin": "all"},
        ],
    }


def test_drags_file_round_trip(tmp_path):
    lift = DragStep(pins=[[0, 1.2, -0.15]], grab=[0, 1.0, 0.16], path=[[0, 1.02, 0.16], [0, 1.05, 0.16]])
    drags = Drags([lift, DragStep("all")], meta={"by": "test"})
    write_drags(drags, tmp_path / "d.json")
    back = read_drags(tmp_path / "d.json")
    assert len(back) == 2 and back.meta == {"by": "test"} and back.source == str(tmp_path / "d.json")
    np.testing.assert_array_equal(back.steps[0].path, drags.steps[0].path)
    assert back.steps[1].unpin == "all" and back.steps[1].grab is None
    d = json.loads((tmp_path / "d.json").read_text())
    assert d["format"] == "kitsuke.drags" and d["steps"][1] == {"unpin": "all"}
    empty = drags_from_dict({"format": "kitsuke.drags", "version": 1, "steps": [{"pins": [], "unpin": []}]})
    assert empty.steps[0].pins.shape == (0, 3) and empty.steps[0].grab is None


@pytest.mark.parametrize(
    ("step", "message"),
    [
        ({"grab": [0, 1, float("nan")], "path": [[0, 1, 0]]}, "NaN"),
        ({"path": [[0, 1, 0]]}, "needs a grab"),
        ({"grab": [0, 1, 0], "pull": []}, "unknown field"),
        ({"unpin": "some"}, "unpin must be"),
        ({"pins": [[0, 1]]}, "points"),
        ({"grab": [[0, 1, 0], [0, 1, 1]]}, "one point"),
    ],
)
def test_bad_drags_files_name_the_file(tmp_path, step, message):
    path = tmp_path / "bad.json"
    path.write_text(json.dumps({"format": "kitsuke.drags", "version": 1, "steps": [step]}))
    with pytest.raises(InputError, match=message) as e:
        read_drags(path)
    assert str(path) in str(e.value)
    for top in ({"format": "kitsuke.strokes", "version": 1, "steps": []}, {"format": "kitsuke.drags", "version": 2}):
        with pytest.raises(InputError):
            drags_from_dict(top)


def test_apply_drags_is_all_or_nothing(body, body_surface, skirt_obj, collider):
    """A file whose second step grabs off the garment: the error names the file and the step, and the garment is
    as it was before the first step (which did move it)."""
    s = DragSession(body, read_garment_obj(skirt_obj), collider=collider)
    x0 = s.positions.copy()
    d = lift_file(x0, body_surface)
    d["steps"][1] = {"grab": [0.0, 2.5, 0.0], "path": [[0.0, 1.0, 0.2]]}
    drags = drags_from_dict(d)
    drags.source = "lift.json"
    with pytest.raises(InputError, match=r"lift.json: step 1: grab point .* is off the garment"):
        apply_drags(s, drags)
    assert (s.positions == x0).all() and not s.pinned.any() and s.grabbed is None
    good = drags_from_dict(lift_file(x0, body_surface))
    results = apply_drags(s, good)
    assert results[0].grabbed >= 0 and len(results[0].pinned) == 1 and len(results[0].moves) == 2
    assert results[1].unpinned == results[0].pinned and not s.pinned.any()
    assert np.linalg.norm(s.positions - x0, axis=1).max() > 0.03


def test_cli_replays_a_drags_file(cli, body_surface, skirt_obj, tmp_path):
    drags = tmp_path / "lift.json"
    drags.write_text(json.dumps(lift_file(read_garment_obj(skirt_obj).positions, body_surface)))
    out, report, png = tmp_path / "out.obj", tmp_path / "r.json", tmp_path / "v.png"
    r = cli("drag", "--body", "default", "--garment", skirt_obj, "--drags", drags, "-o", out, "--report", report,
            "--png", png)  # fmt: skip
    assert r.code == 0, r.err
    before, after = read_garment_obj(skirt_obj), read_garment_obj(out)
    assert after.name == "skirt" and np.array_equal(after.faces, before.faces)
    np.testing.assert_allclose(after.corner_uv, before.corner_uv, atol=1e-7)  # the rest shape travels on
    assert before.contact_offset_m is None and after.contact_offset_m == 0.001  # it says what it was dragged at
    lift = after.positions[:, 1] - before.positions[:, 1]
    assert lift.max() > 0.035 and np.median(lift) > 0.005
    rep = json.loads(report.read_text())
    assert rep["vertices"] == len(before.positions) and len(rep["steps"]) == 2
    assert rep["steps"][0]["updates"] >= 4 and rep["quality_after"]["penetration_count"] == 0
    assert rep["quality_before"]["strain_max"] < 0.01 and rep["update_ms_median"] > 0
    release = rep["steps"][0]["release"]  # what the release did; the let-go point kept where it was left
    assert release["release_s"] > 0 and release["grab_gave_m"] == 0 and release["polished"] in (True, False)
    assert release["strain_max"] == pytest.approx(rep["quality_after"]["strain_max"], abs=1e-5)
    assert rep["steps"][1]["release"] is None  # the unpin step grabs nothing
    assert png.stat().st_size > 10_000
    assert "wrote" in r.err and "2 steps" in r.err


def test_cli_bad_input_exits_2_naming_the_file(cli, body_surface, skirt_obj, tmp_path):
    out = tmp_path / "out.obj"
    bad = tmp_path / "nan.json"
    bad.write_text('{"format": "kitsuke.drags", "version": 1, "steps": [{"grab": [0, NaN, 0], "path": []}]}')
    r = cli("drag", "--body", "default", "--garment", skirt_obj, "--drags", bad, "-o", out)
    assert r.code == 2 and str(bad) in r.err and "NaN" in r.err
    assert len(r.err.strip().splitlines()) == 1 and "Traceback" not in r.err and not out.exists()
    far = tmp_path / "far.json"
    d = lift_file(read_garment_obj(skirt_obj).positions, body_surface)
    d["steps"][0]["path"][1] = [0.0, 0.9, 1.5]  # off the body
    far.write_text(json.dumps(d))
    r = cli("drag", "--body", "default", "--garment", skirt_obj, "--drags", far, "-o", out)
    assert r.code == 2 and "step 0" in r.err and "off the body" in r.err and not out.exists()
    r = cli("drag", "--body", "default", "--garment", skirt_obj, "--drags", far, "-o", skirt_obj)
    assert r.code == 2 and "overwrite" in r.err
    r = cli("drag", "--help")
    assert r.code == 0 and "examples" in r.out and "--drags" in r.out
