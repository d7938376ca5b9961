"""Benchmark of the kimono in motion: simulated frames per second and per-frame quality of the kimono on a walking
body, and the time to calibrate E by simulation.

Run: `python benchmarks/bench_kimono_sim.py [--frames 90] [--substeps 20] [--calibrate] [--json out.json]`.
Targets (issue 26): at least 30 simulated frames per second for the ~5k-vertex kimono on a walking BVH clip on 2
cores, with every frame within the quality targets (no vertex more than 5 mm inside the body, max strain 10 %);
calibration at most 2 minutes per kimono on 2 cores.

The kimono is `kitsuke.tryon.default_simulation_kimono()` (the default kimono dressed at 2.5 cm) on the default
body; the motion is the CMU walk in tests/data (every 4th frame: 30 fps), its legs corrected for a kimono, after the
lead-in from the rest pose. Time is the solver's step alone (`FrameQuality.step_s`: skinning, collision, XPBD),
summed over the frames; measuring quality is not included. The clip-frame figures leave the lead-in out.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
WALK = ROOT / "tests" / "data" / "pose" / "cmu_131_01_start_walk_stop.bvh"


def simulate(frames: int, substeps: int) -> dict:
    """The walk simulated; the figures of `KimonoMotion.summary` and a few percentiles."""
    from kitsuke.body import default_body
    from kitsuke.pose import load_bvh
    from kitsuke.tryon import SimulationSettings, default_simulation_kimono, simulate_kimono

    body = default_body()
    t = time.perf_counter()
    kimono = default_simulation_kimono(body)
    dress_s = time.perf_counter() - t
    settings = SimulationSettings()
    settings = replace(settings, dynamics=replace(settings.dynamics, substeps=substeps))
    poses = load_bvh(WALK, stride=4, max_frames=frames)
    motion = simulate_kimono(poses, body=body, garment=kimono, settings=settings)
    s = motion.summary()
    clip = [q for q in s.pop("per_frame") if not q["lead_in"]]
    steps = np.array([q["step_s"] for q in clip])
    strain_max = np.array([q["strain_max"] for q in clip])
    return {
        "vertices": s["vertices"],
        "substeps": substeps,
        "dress_s": round(dress_s, 2),
        "clip_frames": s["clip_frames"],
        "lead_in_frames": s["lead_in_frames"],
        "clip_fps": round(len(steps) / float(steps.sum()), 2),
        "ms_per_frame_median": round(1e3 * float(np.median(steps)), 1),
        "frames_within_targets": s["frames_within_targets"],
        "strain_max_median": round(float(np.median(strain_max)), 3),
        "strain_max_worst": round(float(strain_max.max()), 3),
        "strain_mean_worst": round(max(q["strain_mean"] for q in clip), 4),
        "penetration_count_worst": s["worst"]["penetration_count"],
        "penetration_deepest_mm": s["worst"]["penetration_deepest_mm"],
    }


def calibration(workers: int) -> dict:
    from kitsuke.body import default_body
    from kitsuke.tryon import default_simulation_kimono
    from kitsuke.tryon.calibrate import CalibrationSettings, calibrate

    body = default_body()
    t = time.perf_counter()
    kimono = default_simulation_kimono(body)
    dress_s = time.perf_counter() - t
    result = calibrate(kimono, body, settings=CalibrationSettings(workers=workers))
    frames = sum(r["frames"] for spreads in result.spreads.values() for r in spreads)
    return {
        "dress_s": round(dress_s, 1),
        "calibrate_s": round(result.seconds, 1),
        "total_s": round(dress_s + result.seconds, 1),
        "spreads": sum(len(v) for v in result.spreads.values()),
        "simulated_frames": frames,
        "workers": workers,
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--frames", type=int, default=90, help="clip frames of the walk (30 fps)")
    ap.add_argument("--substeps", type=int, nargs="+", default=[20], help="solver substeps per frame to compare")
    ap.add_argument("--calibrate", action="store_true", help="also time `kimono calibrate` (12 angles x 2 pairs)")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--json", type=Path, help="write the figures here")
    args = ap.parse_args()
    out: dict = {
        "machine": f"{platform.machine()}, {os.cpu_count()} cores, {platform.processor() or 'cpu'}",
        "load_average": [round(x, 2) for x in os.getloadavg()],
        "simulation": [],
    }
    print("| substeps | vertices | clip frames | simulated fps | ms/frame (median) | frames within targets | "
          "max strain median / worst | worst vertices > 5 mm inside (deepest mm) |")  # fmt: skip
    print("|---|---|---|---|---|---|---|---|")
    for n in args.substeps:
        r = simulate(args.frames, n)
        out["simulation"].append(r)
        print(
            f"| {n} | {r['vertices']} | {r['clip_frames']} | {r['clip_fps']} | {r['ms_per_frame_median']} | "
            f"{r['frames_within_targets']} / {r['clip_frames']} | {r['strain_max_median']} / {r['strain_max_worst']} "
            f"| {r['penetration_count_worst']} ({r['penetration_deepest_mm']}) |"
        )
    if args.calibrate:
        c = calibration(args.workers)
        out["calibration"] = c
        print(f"calibration: dress {c['dress_s']} s + calibrate {c['calibrate_s']} s = {c['total_s']} s "
              f"({c['spreads']} spreads, {c['simulated_frames']} frames, {c['workers']} workers)")  # fmt: skip
    out["load_average_after"] = [round(x, 2) for x in os.getloadavg()]
    if args.json:
        args.json.write_text(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
