"""Fixtures for the pose tests: real clips and mocap from tests/data/pose, extracted once per session."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

POSE_DATA = Path(__file__).parent.parent / "data" / "pose"
BALANCING = POSE_DATA / "pose2sim_balancing_cam01.mp4"
TPOSE_BACK = POSE_DATA / "pose2sim_static_tpose_cam01.mp4"
SQUATS = POSE_DATA / "tfjs_pose_squats.mp4"
SQUATS_EXPECTED = POSE_DATA / "tfjs_pose_squats.expected_blazepose_full.json"
KICK = POSE_DATA / "cmu_10_01_soccer_kick_mh.bvh"
WALK = POSE_DATA / "cmu_131_01_start_walk_stop.bvh"
MH_STANDING = POSE_DATA / "makehuman_standing01_pose.bvh"


@pytest.fixture(scope="session")
def balancing_raw():
    """The balancing clip, every 2nd frame (50 frames at 30 fps), unfiltered MediaPipe poses."""
    from kitsuke.pose import extract_video

    return extract_video(BALANCING, stride=2)


@pytest.fixture(scope="session")
def squats_raw():
    from kitsuke.pose import extract_video

    return extract_video(SQUATS, max_frames=30)


@pytest.fixture(scope="session")
def tpose_back_raw():
    from kitsuke.pose import extract_video

    return extract_video(TPOSE_BACK)


@pytest.fixture(scope="session")
def kick():
    from kitsuke.pose import load_bvh

    return load_bvh(KICK)


@pytest.fixture(scope="session")
def walk():
    from kitsuke.pose import load_bvh

    return load_bvh(WALK)


def write_clip(path: Path, frames: np.ndarray, fps: float = 10.0, faststart: bool = False) -> Path:
    """Write (n, H, W, 3) uint8 RGB frames as an H.264 mp4 with imageio-ffmpeg."""
    import imageio_ffmpeg

    params = ["-movflags", "+faststart"] if faststart else []
    w = imageio_ffmpeg.write_frames(
        str(path),
        (frames.shape[2], frames.shape[1]),
        fps=fps,
        codec="libx264",
        macro_block_size=2,
        output_params=params,
        ffmpeg_log_level="error",
    )
    w.send(None)
    for f in frames:
        w.send(np.ascontiguousarray(f))
    w.close()
    return path
