"""Benchmark of the try-on mirror: throughput, latency and time per stage at 640x480 on this machine.

Run: `python benchmarks/bench_tryon.py [--edge-cm 2.5 4] [--substeps 20 10] [--live-seconds 20] [--json out.json]`.
Targets (the try-on issue): at least 30 frames per second and at most 60 ms from camera frame to shown frame, at
640x480 on 2 cores; registration at most 10 px mean at 640x480 on the shipped videos.

Two measurements per setting:
- **file**: `run_tryon` over every frame of the shipped videos in tests/data/pose (scaled to fit 640x480), one
  frame after the other: the time of each stage, the throughput, and the registration residual;
- **live**: `run_live` on a 30 fps clip played in real time like a camera (the squats clip's frames at 30 fps,
  looped), shown on a display that does nothing: frames shown per second, frames dropped, and the latency from a
  frame's arrival to its display. The pose of the next frame runs in its own thread meanwhile.
The kimono is dressed once per edge length and not timed (`dress_s` gives it).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import tempfile
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
VIDEOS = {
    "squats": ROOT / "tests" / "data" / "pose" / "tfjs_pose_squats.mp4",
    "balancing": ROOT / "tests" / "data" / "pose" / "pose2sim_balancing_cam01.mp4",
}


class NullDisplay:
    def show(self, rgb: np.ndarray) -> None:
        pass

    def key(self) -> str | None:
        return None


def camera_clip(folder: Path, seconds: float) -> Path:
    """The squats clip's frames at 30 fps, looped to `seconds`: a stand-in for a 30 fps camera."""
    from kitsuke.render.video import mp4_writer
    from kitsuke.tryon import open_frames

    frames = [f.rgb for f in open_frames(VIDEOS["squats"])]
    n = int(seconds * 30)
    path = folder / "camera30.mp4"
    with mp4_writer(path, (frames[0].shape[1], frames[0].shape[0]), 30.0) as send:
        for i in range(n):
            k = i % (2 * len(frames) - 2)  # back and forth: no jump at the loop
            send(frames[k if k < len(frames) else 2 * len(frames) - 2 - k])
    return path


def measure(edge_cm: float, substeps: int, live_seconds: float, tmp: Path) -> dict:
    from kitsuke.body import default_body
    from kitsuke.tryon import TryOnSettings, default_simulation_kimono, run_tryon
    from kitsuke.tryon.live import run_live

    body = default_body()
    t = time.perf_counter()
    kimono = default_simulation_kimono(body, edge_cm=edge_cm)
    dress_s = time.perf_counter() - t
    settings = TryOnSettings(edge_cm=edge_cm)
    settings = replace(settings, dynamics=replace(settings.dynamics, substeps=substeps))
    out: dict = {"edge_cm": edge_cm, "substeps": substeps, "dress_s": round(dress_s, 2), "file": {}}
    for name, video in VIDEOS.items():
        run = run_tryon(video, tmp / f"{name}.mp4", settings=settings, garment=kimono)
        s = run.summary()
        out["vertices"] = int(len(kimono.positions))
        out["file"][name] = {
            "size": s["source"]["size"],
            "frames": s["frames"],
            "fps": s["speed"]["fps"],
            "stage_ms_mean": s["speed"]["stage_ms_mean"],
            "registration_mean_px_640x480": s["registration"]["scaled_mean_px"],
            "registration_p95_px": s["registration"]["p95_px"],
            "strain_max_median": s["kimono_strain_max"]["median"],
        }
    if live_seconds > 0:
        clip = camera_clip(tmp, live_seconds)
        run = run_live(clip, NullDisplay(), settings=settings, garment=kimono)
        s = run.summary()
        lat = np.array(run.latency_s) * 1e3
        out["live"] = {
            "source_fps": 30.0,
            "shown_fps": s["speed"]["fps"],
            "frames_shown": s["frames"],
            "frames_dropped": s["frames_dropped"],
            "latency_ms_median": round(float(np.median(lat)), 1),
            "latency_ms_p95": round(float(np.percentile(lat, 95)), 1),
            "stage_ms_mean": s["speed"]["stage_ms_mean"],
        }
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--edge-cm", type=float, nargs="+", default=[2.5, 4.0])
    ap.add_argument("--substeps", type=int, nargs="+", default=[20])
    ap.add_argument("--live-seconds", type=float, default=20.0)
    ap.add_argument("--json", type=Path)
    args = ap.parse_args()
    results = []
    with tempfile.TemporaryDirectory() as d:
        for edge in args.edge_cm:
            for sub in args.substeps:
                r = measure(edge, sub, args.live_seconds, Path(d))
                results.append(r)
                print(json.dumps(r, indent=1), flush=True)
    machine = {"machine": platform.processor() or platform.machine(), "cores": os.cpu_count(), "load": os.getloadavg()}
    print(
        "\n| edge cm | vertices | substeps | file fps (squats, balancing) | stage ms: pose / simulate / render |"
        " registration px @640x480 | live fps shown | live latency ms median / p95 | dropped |"
    )
    print("|---|---|---|---|---|---|---|---|---|")
    for r in results:
        f = r["file"]
        st = f["squats"]["stage_ms_mean"]
        live = r.get("live", {})
        print(
            f"| {r['edge_cm']} | {r['vertices']} | {r['substeps']} | {f['squats']['fps']}, {f['balancing']['fps']} | "
            f"{st.get('pose', 0):.0f} / {st.get('simulate', 0):.0f} / {st.get('render', 0):.0f} | "
            f"{f['squats']['registration_mean_px_640x480']}, {f['balancing']['registration_mean_px_640x480']} | "
            f"{live.get('shown_fps')} | {live.get('latency_ms_median')} / {live.get('latency_ms_p95')} | "
            f"{live.get('frames_dropped')} |"
        )
    print(machine)
    if args.json:
        args.json.write_text(json.dumps({"machine": machine, "results": results}, indent=1))


if __name__ == "__main__":
    main()
