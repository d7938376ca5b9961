"""`kitsuke pose extract|correct` end to end: files, summary, plot, overlay video, and bad input (exit 2)."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest
from PIL import Image

from kitsuke.pose import read_poses

from .conftest import BALANCING, KICK


@pytest.fixture(scope="module")
def extracted(tmp_path_factory):
    from kitsuke.cli import main

    out = tmp_path_factory.mktemp("cli") / "poses.json"
    assert main(["pose", "extract", str(BALANCING), "-o", str(out), "--stride", "3"]) == 0
    return out


def test_extract_writes_a_filtered_sequence(extracted):
    s = read_poses(extracted)
    assert s.n_frames == 34 and s.valid.all() and s.fps == 20
    assert s.source["kind"] == "video" and s.source["filter"]["min_cutoff_hz"] == 1.0
    assert s.image is not None and s.source["size"] == [1080, 1920]


def test_correct_with_plot_video_and_summary(extracted, tmp_path, run_cli):
    out, png, mp4, summ = tmp_path / "c.json", tmp_path / "legs.png", tmp_path / "overlay.mp4", tmp_path / "s.json"
    r = run_cli("pose", "correct", extracted, "-o", out, "--plot", png, "--video", mp4, "--summary", summ)
    assert r.code == 0, r.err
    summary = json.loads(r.out)
    assert summary == json.loads(summ.read_text())
    assert summary["corrected_frames"] > 5 and summary["invariants"]["ok"] and summary["residual_mm"]["max"] == 0
    c = read_poses(out)
    assert c.raw_positions is not None and any(c.corrected) and c.constraints.source == "calibrated"
    with Image.open(png) as im:
        assert im.size[0] > 800 and np.asarray(im.convert("L")).std() > 10
    import imageio_ffmpeg

    reader = imageio_ffmpeg.read_frames(str(mp4))
    meta = next(reader)
    frames = list(reader)
    assert meta["codec"] == "h264" and meta["size"] == (720, 1280) and len(frames) == c.n_frames
    assert meta["fps"] == pytest.approx(20)
    # the camera fitted to the detections, reported in source pixels (1080x1920 here)
    fit = summary["overlay"]["fit_residual_px"]
    assert 0 < fit["mean"] <= fit["p95"] <= fit["worst"] and fit["mean"] < 40


def test_overlay_draws_the_detected_landmarks(extracted):
    """The raw skeleton is the 2D detection itself, and joints the correction left alone stay on it."""
    from kitsuke.pose import correct_poses
    from kitsuke.pose._output import image_skeletons

    c = correct_poses(read_poses(extracted))
    f = int(np.flatnonzero(c.rotated.any(axis=1))[0])
    raw, corrected, residual = image_skeletons(c.poses, f, 0.5)
    assert np.array_equal(raw, c.poses.image[f, :, :2] * 0.5)
    moved = np.linalg.norm(c.poses.positions[f] - c.poses.raw_positions[f], axis=1) > 0
    assert moved.any() and np.array_equal(corrected[~moved], raw[~moved])
    assert (np.linalg.norm(corrected[moved] - raw[moved], axis=1) > 1).any()
    assert np.nanmax(residual) < 200


def test_side_by_side_video(extracted, tmp_path, run_cli):
    out, mp4 = tmp_path / "c.json", tmp_path / "sbs.mp4"
    r = run_cli("pose", "correct", extracted, "-o", out, "--video", mp4, "--side-by-side")
    assert r.code == 0, r.err
    import imageio_ffmpeg

    reader = imageio_ffmpeg.read_frames(str(mp4))
    meta = next(reader)
    frames = [np.frombuffer(b, np.uint8).reshape(1280, 1440, 3) for b in reader]
    assert meta["codec"] == "h264" and meta["size"] == (1440, 1280) and len(frames) == read_poses(out).n_frames
    # two different panels: the right one has the corrected skeleton and the legend
    assert np.abs(frames[0][:, :720].astype(int) - frames[0][:, 720:].astype(int)).mean() > 0.5


def test_missing_output_folder_is_refused(tmp_path, extracted, run_cli):
    target = tmp_path / "nope" / "poses.json"
    for args in (["pose", "correct", extracted, "-o", target], ["pose", "extract", extracted, "-o", target]):
        r = run_cli(*args)
        assert r.code == 2 and "does not exist" in r.err and r.err.count("\n") == 1, r.err
    r = run_cli("pose", "correct", extracted, "-o", tmp_path / "c.json", "--video", tmp_path / "nope" / "v.mp4")
    assert r.code == 2 and "does not exist" in r.err
    assert not (tmp_path / "nope").exists()


def test_no_person_is_a_warning(tmp_path, run_cli):
    blank = tmp_path / "empty_room.png"
    Image.fromarray(np.full((240, 320, 3), 90, np.uint8)).save(blank)
    r = run_cli("pose", "extract", blank, "-o", tmp_path / "p.json")
    assert r.code == 0 and "warning: no person found in the image" in r.err


def test_correct_bvh_draws_synthetic_views(tmp_path, run_cli):
    out, mp4 = tmp_path / "k.json", tmp_path / "k.mp4"
    r = run_cli("pose", "correct", KICK, "-o", out, "--video", mp4, "--max-frames", "60", "--stride", "3")
    assert r.code == 0, r.err
    import imageio_ffmpeg

    reader = imageio_ffmpeg.read_frames(str(mp4))
    meta = next(reader)
    assert meta["codec"] == "h264" and meta["size"] == (960, 540) and len(list(reader)) == 60


def test_bad_inputs_exit_2_with_one_line(tmp_path, extracted, run_cli):
    before = extracted.read_bytes()
    cases = [
        (["pose", "correct", tmp_path / "missing.mp4", "-o", tmp_path / "o.json"], "missing.mp4: not found"),
        (["pose", "correct", extracted, "-o", extracted], "refusing to overwrite an input"),
        (["pose", "correct", extracted, "-o", tmp_path / "o.json", "--plot", tmp_path / "p.jpg"], "must be a .png"),
        (["pose", "extract", "-o", tmp_path / "o.json"], "give either SOURCE or --camera"),
        (["pose", "extract", extracted, "--camera", "0", "-o", tmp_path / "o.json"], "give either SOURCE"),
        (["pose", "extract", "--camera", "57", "-o", tmp_path / "o.json"], "camera 57: cannot open the camera"),
        (["pose", "extract", extracted, "-o", tmp_path / "o.json", "--stride", "0"], "--stride must be at least 1"),
    ]
    for args, message in cases:
        r = run_cli(*args)
        assert r.code == 2, (args, r.err)
        assert message in r.err and r.err.count("\n") == 1 and "Traceback" not in r.err
    assert not (tmp_path / "o.json").exists() and extracted.read_bytes() == before


def test_help_and_a_real_process(tmp_path):
    r = subprocess.run([sys.executable, "-m", "kitsuke", "pose", "correct", "--help"], capture_output=True, text=True)
    assert r.returncode == 0
    for word in ("examples:", "--constraints", "--plot", "--video", "H.264", "E(θ)", "--no-filter", "Hz"):
        assert word in r.stdout
    out = tmp_path / "kick.json"
    r = subprocess.run(
        [sys.executable, "-m", "kitsuke", "pose", "correct", str(KICK), "-o", str(out)], capture_output=True, text=True
    )
    assert r.returncode == 0 and r.stderr == ""  # quiet when not on a terminal
    assert json.loads(r.stdout)["corrections"]["knee"] > 10 and read_poses(out).n_frames == 201  # 18 measured
