"""Soak test of the live try-on: a looped clip played like a camera for many minutes, checking that nothing grows
or drifts.

Run: `python benchmarks/soak_tryon.py [--minutes 10] [--edge-cm 4] [--json soak.json]`.
Target (the try-on issue): memory flat within ±5 % (resident set size, after the first minute's warm-up), a stable
frame time, and no accumulated error: the kimono stays on the body (the cloth's median distance to the skin, its
largest strain) and registered (residual) as in the first minute.

The clip is the balancing video (60 fps, 100 frames) played forwards and backwards at its own rate, looped for the
whole run, through `kitsuke.tryon.live.run_live` on a display that shows nothing. Per minute: frames shown, median
frame interval, resident memory, median registration residual, median cloth-to-skin distance and
median of the largest strain.
"""

from __future__ import annotations

import argparse
import json
import os
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
CLIP = ROOT / "tests" / "data" / "pose" / "pose2sim_balancing_cam01.mp4"


def rss_mb() -> float:
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 2**20


def looped_clip(folder: Path, minutes: float) -> Path:
    from kitsuke.render.video import mp4_writer
    from kitsuke.tryon import open_frames

    src = open_frames(CLIP)
    frames = [f.rgb for f in src]
    cycle = frames + frames[-2:0:-1]  # forwards then backwards: no jump where it loops
    n = int(minutes * 60 * src.fps)
    path = folder / "looped.mp4"
    with mp4_writer(path, src.size, src.fps) as send:
        for i in range(n):
            send(cycle[i % len(cycle)])
    return path


class NullDisplay:
    def show(self, rgb: np.ndarray) -> None:
        pass

    def key(self) -> str | None:
        return None


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--minutes", type=float, default=10.0)
    ap.add_argument("--edge-cm", type=float, default=4.0)
    ap.add_argument("--json", type=Path)
    args = ap.parse_args()
    from kitsuke.tryon import TryOnSettings
    from kitsuke.tryon.live import run_live

    rows_raw: list[tuple] = []  # per shown frame: time, RSS, latency, residual, cloth-to-skin, strain

    def record(out, mirror) -> None:  # noqa: ANN001
        sim = mirror.kimono.sim
        off = float(np.median(sim.state.contacts.distance)) if sim is not None else np.nan
        rows_raw.append((time.perf_counter(), rss_mb(), out.residual_px, off, out.strain_max))

    with tempfile.TemporaryDirectory() as d:
        clip = looped_clip(Path(d), args.minutes)
        t0 = time.perf_counter()
        run = run_live(clip, NullDisplay(), settings=TryOnSettings(edge_cm=args.edge_cm), on_frame=record)
    a = np.array(rows_raw, dtype=np.float64)
    t, mem = a[:, 0] - t0, a[:, 1]
    rows = []
    for m in range(int(np.ceil(t[-1] / 60.0))):
        sel = (t >= 60 * m) & (t < 60 * (m + 1))
        if sel.sum() < 2:
            continue
        row = {
            "minute": m + 1,
            "frames": int(sel.sum()),
            "frame_interval_ms": round(float(np.median(np.diff(t[sel]))) * 1e3, 1),
            "rss_mb": round(float(np.median(mem[sel])), 1),
            "residual_px": round(float(np.nanmedian(a[sel, 2])), 2),
            "cloth_to_skin_mm": round(float(np.nanmedian(a[sel, 3])) * 1e3, 1),
            "strain_max": round(float(np.nanmedian(a[sel, 4])), 4),
        }
        rows.append(row)
        print(json.dumps(row), flush=True)
    after_warmup = mem[t >= 60.0] if (t >= 60.0).any() else mem
    growth = (after_warmup.max() - after_warmup.min()) / after_warmup.min()
    summary = {
        "minutes": args.minutes,
        "edge_cm": args.edge_cm,
        "frames_shown": run.counts["frames"],
        "latency_ms_median_last_frames": round(float(np.median(run.latency_s)) * 1e3, 1),
        "frames_dropped": run.dropped,
        "rss_mb_after_first_minute": [round(float(after_warmup.min()), 1), round(float(after_warmup.max()), 1)],
        "rss_spread_pct": round(100 * float(growth), 2),
        "within_5pct": bool(growth <= 0.05),
        "machine": {"cores": os.cpu_count(), "load": os.getloadavg()},
    }
    print(json.dumps(summary, indent=1))
    print("\n| minute | frames | frame interval ms | RSS MB | residual px | cloth-skin mm | strain |")
    print("|---|---|---|---|---|---|---|")
    for r in rows:
        print(
            f"| {r['minute']} | {r['frames']} | {r['frame_interval_ms']} | {r['rss_mb']} | "
            f"{r['residual_px']} | {r['cloth_to_skin_mm']} | {r['strain_max']} |"
        )
    if args.json:
        args.json.write_text(json.dumps({"summary": summary, "per_minute": rows}, indent=1))


if __name__ == "__main__":
    main()
