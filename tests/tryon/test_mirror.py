"""The try-on mirror: registration, compositing, the file runner, the live path (headless) and bad inputs."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

import numpy as np
import pytest

from kitsuke.body import default_body
from kitsuke.skeleton import INDEX
from kitsuke.tryon import LIVE_EDGE_CM, TryOnSettings, default_simulation_kimono, fit_focal, register, run_tryon
from kitsuke.tryon.frames import Frame, Latest, open_frames, working_size
from kitsuke.tryon.register import KITSUKE_TO_CAMERA, Registration, focal_px

POSE_DATA = Path(__file__).parent.parent / "data" / "pose"
SQUATS = POSE_DATA / "tfjs_pose_squats.mp4"
BALANCING = POSE_DATA / "pose2sim_balancing_cam01.mp4"
FAST = TryOnSettings(edge_cm=LIVE_EDGE_CM)


@pytest.fixture(scope="module")
def body():
    return default_body()


@pytest.fixture(scope="module")
def kimono(body):
    return default_simulation_kimono(body, edge_cm=LIVE_EDGE_CM)


def _ffprobe(path: Path) -> tuple[str, int]:
    """(codec, frame count) as ffmpeg reads the file."""
    import imageio_ffmpeg

    out = subprocess.run(
        [imageio_ffmpeg.get_ffmpeg_exe(), "-i", str(path), "-map", "0:v:0", "-c", "copy", "-f", "null", "-"],
        capture_output=True,
        text=True,
    ).stderr
    codec = "h264" if "Video: h264" in out else out
    frames = int(out.rsplit("frame=", 1)[1].split()[0])
    return codec, frames


# ------------------------------------------------------------------------------------------------ registration


def _camera_case(body, fov=55.0, size=(480, 640), noise_px=0.0, seed=0):
    joints = body.rig.joints
    turn = np.radians(20.0)
    rot = KITSUKE_TO_CAMERA @ np.array([[np.cos(turn), 0, np.sin(turn)], [0, 1, 0], [-np.sin(turn), 0, np.cos(turn)]])
    truth = Registration(focal_px(size, fov), size, rot, np.array([0.1, 0.9, 3.2]), np.zeros(len(joints)))
    uv = truth.project(joints) + np.random.default_rng(seed).normal(0, noise_px, (len(joints), 2))
    image = np.c_[uv, np.ones(len(joints))]
    return truth, joints, image


def test_register_recovers_a_known_camera(body):
    truth, joints, image = _camera_case(body)
    got = register(joints, image, truth.focal_px, truth.size)
    assert got is not None
    assert got.mean_residual_px < 1e-3
    np.testing.assert_allclose(got.rotation, truth.rotation, atol=1e-6)
    np.testing.assert_allclose(got.translation, truth.translation, atol=1e-5)


def test_the_render_camera_projects_like_the_registration(body):
    """The kimono is drawn with `Registration.camera()`: it must put every point where the fit put it."""
    truth, joints, _ = _camera_case(body)
    np.testing.assert_allclose(truth.camera().project(joints, truth.size), truth.project(joints), atol=1e-6)


def test_fit_focal_finds_the_field_of_view(body):
    frames = [_camera_case(body, fov=50.0, noise_px=1.0, seed=s)[1:] for s in range(6)]
    # the body at different distances and turns: one frame alone cannot tell focal length from distance well
    f = fit_focal(frames, (480, 640))
    fov = 2 * np.degrees(np.arctan(0.5 * 640 / f))
    assert abs(fov - 50.0) < 8.0


def test_register_refuses_too_few_joints(body):
    _, joints, image = _camera_case(body)
    image[5:, 2] = 0.1  # hardly seen
    assert register(joints, image, 500.0, (480, 640)) is None


def test_working_size_fits_640x480_either_way():
    assert working_size((1920, 1080)) == (640, 360)
    assert working_size((1080, 1920)) == (360, 640)
    assert working_size((320, 240)) == (320, 240)  # never scaled up
    w, h = working_size((1001, 777))
    assert w % 2 == 0 and h % 2 == 0


# -------------------------------------------------------------------------------------------- the file runner


@pytest.fixture(scope="module")
def squats_run(tmp_path_factory, kimono):
    out = tmp_path_factory.mktemp("tryon")
    run = run_tryon(
        SQUATS, out / "squats.mp4", report=out / "squats.json", settings=FAST, garment=kimono, max_frames=20
    )
    return out, run


def test_tryon_writes_h264_with_every_frame(squats_run):
    out, run = squats_run
    codec, frames = _ffprobe(out / "squats.mp4")
    assert codec == "h264"
    assert frames == 20 == len(run.frames)


def test_tryon_registers_within_target_and_reports_it(squats_run):
    out, _ = squats_run
    report = json.loads((out / "squats.json").read_text())
    assert report["frames_with_pose"] == 20
    assert report["registration"]["scaled_mean_px"] <= 10.0
    assert report["registration"]["p95_px"] > report["registration"]["mean_px"]
    assert {"pose", "simulate", "register", "render"} <= set(report["speed"]["stage_ms_mean"])
    assert len(report["per_frame"]) == 20 and report["warnings"] == []


def test_the_kimono_covers_the_trunk_and_leaves_the_head(kimono):
    """Drawn over the frame, the kimono covers the person's hips and chest, and not their head."""
    from kitsuke.tryon import TryOn

    src = open_frames(SQUATS)
    with TryOn(FAST, garment=kimono) as mirror:
        for k, frame in enumerate(src):
            seen = mirror.observe(frame)
            out = mirror.dress(frame, seen)
            if k == 12:
                break
    changed = np.abs(out.image.astype(int) - frame.rgb.astype(int)).sum(axis=2) > 30
    uv = seen.image

    def covered(joint: str, r: int = 3) -> float:
        u, v = np.round(uv[INDEX[joint], :2]).astype(int)
        return changed[v - r : v + r + 1, u - r : u + r + 1].mean()

    assert covered("pelvis") > 0.8 and covered("chest") > 0.8
    assert covered("head") < 0.2
    assert 0.05 < changed.mean() < 0.5  # a kimono, not the whole frame


def test_compare_puts_uncorrected_and_corrected_side_by_side(tmp_path, kimono):
    run = run_tryon(
        BALANCING, tmp_path / "c.mp4", compare=True, plot=tmp_path / "legs.png", settings=FAST, garment=kimono,
        max_frames=8,
    )  # fmt: skip
    import cv2

    ok, first = cv2.VideoCapture(str(tmp_path / "c.mp4")).read()
    assert ok and first.shape[1] == 2 * run.source["size"][0]
    assert (tmp_path / "legs.png").stat().st_size > 10_000


# ---------------------------------------------------------------------------------------------- bad inputs


def _write_video(path: Path, frames: list[np.ndarray], fps: float = 10.0) -> Path:
    from kitsuke.render.video import mp4_writer

    with mp4_writer(path, (frames[0].shape[1], frames[0].shape[0]), fps) as send:
        for f in frames:
            send(f)
    return path


@pytest.fixture(scope="module")
def squat_frames():
    return [f.rgb for _, f in zip(range(24), open_frames(SQUATS), strict=False)]


def test_no_person_keeps_the_frames_and_says_so(tmp_path, kimono):
    blank = [np.full((240, 320, 3), 120, np.uint8) for _ in range(6)]
    run = run_tryon(_write_video(tmp_path / "empty.mp4", blank), tmp_path / "o.mp4", settings=FAST, garment=kimono)
    assert run.summary()["frames_with_pose"] == 0
    assert any("no person" in w for w in run.warnings())
    assert _ffprobe(tmp_path / "o.mp4")[1] == 6


def test_a_person_leaving_fades_the_kimono_and_is_dressed_again(tmp_path, kimono, squat_frames):
    blank = np.full_like(squat_frames[0], 128)
    frames = squat_frames[:8] + [blank] * 14 + squat_frames[8:14]  # 10 fps: 1.4 s without the person
    run = run_tryon(_write_video(tmp_path / "gap.mp4", frames), tmp_path / "o.mp4", settings=FAST, garment=kimono)
    alpha = [f.alpha for f in run.frames]
    posed = [f.posed for f in run.frames]
    assert all(posed[:8]) and not any(posed[8:22]) and sum(posed[22:]) >= 4
    gap = alpha[8:22]
    assert gap[0] > 0.8 and all(a >= b for a, b in zip(gap, gap[1:], strict=False)) and gap[-1] == 0.0
    assert alpha[-1] == 1.0
    assert run.summary()["frames_without_pose"] == 14


def test_two_people_dress_the_larger(tmp_path, kimono, squat_frames):
    import cv2

    def pair(rgb):
        h, w = rgb.shape[:2]
        small = cv2.resize(rgb, (w // 2, h // 2))
        canvas = np.full((h, w + w // 2, 3), 200, np.uint8)
        canvas[:, :w] = rgb
        canvas[h // 2 :, w:] = small
        return canvas

    frames = [pair(f) for f in squat_frames[:6]]
    run = run_tryon(_write_video(tmp_path / "two.mp4", frames), tmp_path / "o.mp4", settings=FAST, garment=kimono)
    s = run.summary()
    assert s["frames_with_pose"] == 6
    assert s["registration"]["mean_px"] < 15.0  # registered to the large person (the small one would not fit)
    assert s["frames_with_several_people"] >= 4  # both seen
    assert any("followed" in w for w in run.warnings())


def test_corrupt_images_and_a_cut_video_do_not_crash(tmp_path, kimono, squat_frames):
    from PIL import Image

    folder = tmp_path / "imgs"
    folder.mkdir()
    for i, f in enumerate(squat_frames[:5]):
        Image.fromarray(f).save(folder / f"{i:03d}.png")
    (folder / "002.png").write_bytes(b"not a png at all")
    # a person cut off at the knees: the frame's top half only
    Image.fromarray(np.ascontiguousarray(squat_frames[5][: squat_frames[5].shape[0] // 2])).resize(
        squat_frames[0].shape[1::-1]
    ).save(folder / "005.png")
    run = run_tryon(folder, tmp_path / "o.mp4", settings=FAST, garment=kimono)
    assert run.skipped == 1 and len(run.frames) == 5
    assert any("did not decode" in w for w in run.warnings())

    whole = _write_video(tmp_path / "whole.mp4", squat_frames[:12])
    data = whole.read_bytes()
    cut = tmp_path / "cut.mp4"
    cut.write_bytes(data[: int(len(data) * 0.6)])
    try:
        run = run_tryon(cut, tmp_path / "o2.mp4", settings=FAST, garment=kimono)
    except Exception as e:  # noqa: BLE001 - an unreadable file may only be refused as bad input
        from kitsuke.errors import InputError

        assert isinstance(e, InputError)
    else:
        assert len(run.frames) < 12


# ------------------------------------------------------------------------------------------------ the live path


class RecordingDisplay:
    """A window stand-in: keeps what is shown and presses keys at given frames."""

    def __init__(self, keys: dict[int, str]) -> None:
        self.keys = keys
        self.shown: list[np.ndarray] = []

    def show(self, rgb: np.ndarray) -> None:
        self.shown.append(rgb)

    def key(self) -> str | None:
        return self.keys.get(len(self.shown))


def test_live_path_headless_with_keys(tmp_path, kimono, squat_frames):
    """The live loop fed by a video paced like a camera: frames are dropped rather than queued, `c` switches the
    correction, `s` saves a snapshot, `q` quits; the shown image is mirrored."""
    from kitsuke.tryon.live import run_live

    camera = _write_video(tmp_path / "camera.mp4", squat_frames * 10, fps=30.0)  # 8 s at 30 fps
    display = RecordingDisplay({3: "c", 4: "s", 9: "q"})
    saved = []
    run = run_live(
        camera, display, settings=FAST, garment=kimono, snapshots=tmp_path / "snaps", on_snapshot=saved.append,
    )  # fmt: skip
    assert len(display.shown) == 9  # ended by q
    assert len(saved) == 1 and saved[0].exists() and saved[0].parent == tmp_path / "snaps"
    # 30 frames a second in, a few a second through the mirror: most are dropped, none queue up
    assert run.dropped > 10
    assert np.median(run.latency_s) < 1.0
    shown, meta = display.shown[2], run.frames[2]
    assert shown.shape[:2] == squat_frames[0].shape[:2]
    assert meta.posed and run.frames[5].posed
    # flipped like a mirror: the top of the frame (above the kimono) is the source's, left for right
    top = slice(0, 60)
    src = squat_frames[meta.index % len(squat_frames)].astype(int)
    assert np.abs(shown[top, ::-1].astype(int) - src[top]).mean() < 6
    assert np.abs(shown[top].astype(int) - src[top]).mean() > 2 * np.abs(shown[top, ::-1].astype(int) - src[top]).mean()


def test_latest_drops_frames_it_cannot_hand_out():
    src = open_frames(SQUATS)
    latest = Latest(src, paced=False)
    import time

    time.sleep(1.0)  # the reader runs ahead of a consumer that has not started
    got = list(latest)
    assert got and latest.dropped > 0
    assert len(got) + latest.dropped == 65
    assert all(isinstance(f, Frame) for f in got)


@pytest.mark.parametrize("display", [None, ":97", "not-a-display"])
def test_window_without_display_says_so(run_cli, monkeypatch, display):
    """No DISPLAY, or one no X server answers on (OpenCV's Qt would abort the process there): one line, exit 2."""
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    if display is None:
        monkeypatch.delenv("DISPLAY", raising=False)
    else:
        monkeypatch.setenv("DISPLAY", display)
    r = run_cli("tryon", "--camera", "0", "--window")
    assert r.code == 2 and "no display" in r.err
    assert len(r.err.strip().splitlines()) == 1


def test_cli_refuses_bad_arguments(run_cli, tmp_path):
    assert run_cli("tryon", "-o", str(tmp_path / "o.mp4")).code == 2  # no source
    assert run_cli("tryon", str(SQUATS)).code == 2  # nowhere to write
    r = run_cli("tryon", str(tmp_path / "missing.mp4"), "-o", str(tmp_path / "o.mp4"))
    assert r.code == 2 and "missing.mp4" in r.err
    assert not (tmp_path / "o.mp4").exists()


def test_a_failed_simulation_stops_a_file_but_a_mirror_dresses_again(tmp_path, kimono, squat_frames, monkeypatch):
    """A file's run that diverges writes nothing (exit 1 from the CLI); the live mirror re-dresses and counts it."""
    from dataclasses import replace

    from kitsuke.errors import ComputationError
    from kitsuke.tryon import simulate

    clip = _write_video(tmp_path / "clip.mp4", squat_frames[:10])
    calls = {"n": 0}
    advance = simulate.KimonoSimulator.advance

    def failing(self, *a, **k):
        calls["n"] += 1
        if calls["n"] == 20:  # in the 5th frame or so (the first frame's blend takes several)
            raise ComputationError("simulation", "frame 4: the kimono left the body")
        return advance(self, *a, **k)

    monkeypatch.setattr(simulate.KimonoSimulator, "advance", failing)
    with pytest.raises(ComputationError):
        run_tryon(clip, tmp_path / "o.mp4", settings=FAST, garment=kimono)
    assert not (tmp_path / "o.mp4").exists()
    calls["n"] = 0
    run = run_tryon(clip, tmp_path / "o.mp4", settings=replace(FAST, recover=True), garment=kimono)
    s = run.summary()
    assert s["kimono_restarts"] == 1 and s["frames"] == 10
    assert any("dressed afresh" in w for w in run.warnings())
    assert run.frames[-1].alpha == 1.0 and np.isfinite(run.frames[-1].strain_max)


def test_the_person_followed_stays_until_they_leave(tmp_path, kimono, squat_frames):
    """Two people: the larger is followed; when only the other is left, they are dressed afresh (a new kimono
    blended onto them) instead of the first kimono jumping across the frame."""
    import cv2

    h, w = squat_frames[0].shape[:2]

    def scene(rgb, with_large):
        canvas = np.full((h, w + w // 2, 3), 200, np.uint8)
        if with_large:
            canvas[:, :w] = rgb
        canvas[h // 2 :, w:] = cv2.resize(rgb, (w // 2, h // 2))
        return canvas

    frames = [scene(f, True) for f in squat_frames[:6]] + [scene(f, False) for f in squat_frames[6:12]]
    run = run_tryon(_write_video(tmp_path / "leave.mp4", frames), tmp_path / "o.mp4", settings=FAST, garment=kimono)
    switched = [f.index for f in run.frames if f.switched]
    posed = [f.posed for f in run.frames]
    assert all(posed[6:]), "the small person should be found once the large one has gone"
    assert switched and 6 <= switched[0] <= 7 and len(switched) == 1
    assert any("left 1 times" in w for w in run.warnings())


def test_same_person_overlap():
    from kitsuke.tryon.mirror import _box, _iou

    a = np.array([[10, 10, 1.0], [30, 50, 1.0], [20, 30, 0.1]])
    np.testing.assert_allclose(_box(a), [10, 10, 30, 50])
    assert _iou(_box(a), _box(a)) == 1.0
    assert _iou(np.array([0, 0, 10, 10.0]), np.array([5, 0, 15, 10.0])) == pytest.approx(1 / 3)
    assert _iou(np.array([0, 0, 10, 10.0]), np.array([20, 20, 30, 30.0])) == 0.0
