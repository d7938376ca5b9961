"""Benchmark of kitsuke.pose: MediaPipe extraction speed on 640×480 video, and posture-correction time per frame.

Run: `python benchmarks/bench_pose.py` (uses tests/data/pose; prints its figures). Targets (SPEC §8, issue 5):
extraction ~17 ms per 640×480 frame in VIDEO mode; correction < 0.2 ms per frame.
"""

from __future__ import annotations

import argparse
import platform
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np

DATA = Path(__file__).resolve().parent.parent / "tests" / "data" / "pose"


def make_640x480_clip(path: Path, frames: int) -> Path:
    """The balancing clip (1080×1920 portrait) scaled to 270×480 and centred on a grey 640×480 canvas."""
    import cv2
    import imageio_ffmpeg

    cap = cv2.VideoCapture(str(DATA / "pose2sim_balancing_cam01.mp4"))
    w = imageio_ffmpeg.write_frames(
        str(path), (640, 480), fps=60, codec="libx264", macro_block_size=2, ffmpeg_log_level="error"
    )
    w.send(None)
    n = 0
    while n < frames:
        ok, f = cap.read()
        if not ok:
            cap.release()
            cap = cv2.VideoCapture(str(DATA / "pose2sim_balancing_cam01.mp4"))
            continue
        canvas = np.full((480, 640, 3), 128, np.uint8)
        canvas[:, 185:455] = cv2.resize(f, (270, 480))
        w.send(np.ascontiguousarray(canvas[:, :, ::-1]))
        n += 1
    w.close()
    cap.release()
    return path


def bench_extraction(frames: int) -> None:
    import cv2

    from kitsuke.pose import PoseLandmarker, extract_video

    with tempfile.TemporaryDirectory() as d:
        clip = make_640x480_clip(Path(d) / "clip.mp4", frames)
        t0 = time.perf_counter()
        with PoseLandmarker("video"):
            pass
        load = time.perf_counter() - t0
        # decode only
        t0 = time.perf_counter()
        cap = cv2.VideoCapture(str(clip))
        while cap.read()[0]:
            pass
        cap.release()
        decode = (time.perf_counter() - t0) / frames
        t0 = time.perf_counter()
        s = extract_video(clip)
        total = time.perf_counter() - t0
    per = (total - load) / s.n_frames
    print(f"extraction, 640x480, VIDEO mode, {s.n_frames} frames ({int(s.valid.sum())} with a person):")
    print(f"  model load {load * 1e3:.0f} ms; decode {decode * 1e3:.2f} ms/frame")
    print(
        f"  extract_video {per * 1e3:.1f} ms/frame incl. decode -> {1 / per:.1f} fps "
        f"(landmarker alone ~{(per - decode) * 1e3:.1f} ms/frame)"
    )


def bench_correction(repeats: int) -> None:
    from kitsuke.pose import correct_poses, filter_poses, load_bvh

    walk = load_bvh(DATA / "cmu_131_01_start_walk_stop.bvh")
    kick = load_bvh(DATA / "cmu_10_01_soccer_kick_mh.bvh")
    correct_poses(kick)  # compile / load the numba cache
    for name, poses in (("CMU 131 walk, 994 frames", walk), ("CMU 10_01 kick, 201 frames", kick)):
        times, rotated = [], 0
        for _ in range(repeats):
            c = correct_poses(poses)
            times.append(c.seconds)
            rotated = int(c.rotated.any(axis=1).sum())
        best = min(times)
        med = statistics.median(times)
        print(f"correction, {name} ({rotated} frames corrected):")
        print(
            f"  {med / poses.n_frames * 1e3:.4f} ms/frame median, {best / poses.n_frames * 1e3:.4f} ms/frame best, "
            f"{med / max(rotated, 1) * 1e3:.4f} ms per corrected frame"
        )
    t0 = time.perf_counter()
    for _ in range(repeats):
        filter_poses(walk)
    print(f"One-Euro filter: {(time.perf_counter() - t0) / repeats / walk.n_frames * 1e3:.4f} ms/frame")
    t0 = time.perf_counter()
    for _ in range(repeats):
        load_bvh(DATA / "cmu_131_01_start_walk_stop.bvh")
    print(f"BVH load (994 frames, 31 joints): {(time.perf_counter() - t0) / repeats * 1e3:.1f} ms")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--frames", type=int, default=300, help="frames of 640x480 video to extract (default 300)")
    ap.add_argument("--repeats", type=int, default=20, help="repeats of the correction timing (default 20)")
    ap.add_argument("--skip-extraction", action="store_true")
    args = ap.parse_args()
    print(f"machine: {platform.processor() or platform.machine()}, python {platform.python_version()}")
    if not args.skip_extraction:
        bench_extraction(args.frames)
    bench_correction(args.repeats)


if __name__ == "__main__":
    main()
