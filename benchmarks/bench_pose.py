"""Benchmark of kitsuke.pose: the whole pipeline (extract + correct + overlay video) at camera sizes, MediaPipe
extraction alone on 640×480 video, and posture-correction time per frame.

Run: `python benchmarks/bench_pose.py [--sizes 640x480 1920x1080] [--pipeline-frames 200]` (uses tests/data/pose;
prints its figures). Targets: the pipeline at 30 fps or more for 640×480 on 2 cores (the try-on mirror's budget,
issue 25); extraction ~17 ms per 640×480 frame in VIDEO mode; correction < 0.2 ms per frame (issue 5).

The pipeline: each size is made from the balancing clip with ffmpeg (scaled to fit, padded, H.264), then timed in
one process: `extract_video` (decode + inference), `filter_poses` + `correct_poses`, `write_overlay_video` (decode
again, draw, encode H.264), each stage's frames per second and the whole pipeline's; best of `--repeat` runs (the
first also warms numba's cache and MediaPipe's model).
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


def make_clip(size: tuple[int, int], frames: int, out: Path) -> Path:
    import subprocess

    import imageio_ffmpeg

    w, h = size
    vf = f"scale={w}:{h}:force_original_aspect_ratio=decrease,pad={w}:{h}:(ow-iw)/2:(oh-ih)/2"
    cmd = [
        imageio_ffmpeg.get_ffmpeg_exe(),
        "-loglevel",
        "error",
        "-y",
        "-i",
        str(DATA / "pose2sim_balancing_cam01.mp4"),
    ]
    cmd += ["-vf", vf, "-frames:v", str(frames), "-c:v", "libx264", "-preset", "veryfast", "-crf", "20", str(out)]
    subprocess.run(cmd, check=True)
    return out


def pipeline_once(clip: Path, folder: Path) -> dict[str, float]:
    from kitsuke.pose import OneEuroConfig, correct_poses, extract_video, filter_poses, write_overlay_video

    t0 = time.perf_counter()
    poses = extract_video(clip)
    t1 = time.perf_counter()
    correction = correct_poses(filter_poses(poses, OneEuroConfig()))
    t2 = time.perf_counter()
    write_overlay_video(correction, folder / "overlay.mp4")
    t3 = time.perf_counter()
    n = poses.n_frames
    fps = {"extract": n / (t1 - t0), "correct": n / (t2 - t1), "overlay": n / (t3 - t2), "all": n / (t3 - t0)}
    return {"frames": n, **fps}


def bench_pipeline(sizes: list[str], frames: int, repeat: int) -> None:
    print(f"pipeline (extract + correct + overlay), {frames} frames of the balancing clip, best of {repeat}:")
    print(f"  {'size':>10} {'extract fps':>12} {'correct fps':>12} {'overlay fps':>12} {'all fps':>8}")
    with tempfile.TemporaryDirectory() as d:
        folder = Path(d)
        for text in sizes:
            w, h = (int(v) for v in text.lower().split("x"))
            clip = make_clip((w, h), frames, folder / f"clip_{w}x{h}.mp4")
            runs = [pipeline_once(clip, folder) for _ in range(max(1, repeat))]
            b = max(runs, key=lambda r: r["all"])
            print(
                f"  {text:>10} {b['extract']:>12.1f} {b['correct']:>12.0f} {b['overlay']:>12.1f} {b['all']:>8.1f}",
                flush=True,
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
    ap.add_argument("--sizes", nargs="*", default=["640x480", "1920x1080"], help="pipeline sizes (none: skip it)")
    ap.add_argument("--pipeline-frames", type=int, default=200, help="frames per pipeline clip (default 200)")
    ap.add_argument("--repeat", type=int, default=2, help="pipeline runs per size, best kept (default 2)")
    args = ap.parse_args()
    print(f"machine: {platform.processor() or platform.machine()}, python {platform.python_version()}")
    if args.sizes:
        bench_pipeline(args.sizes, args.pipeline_frames, args.repeat)
    if not args.skip_extraction:
        bench_extraction(args.frames)
    bench_correction(args.repeats)


if __name__ == "__main__":
    main()
