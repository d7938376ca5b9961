"""Benchmark: wrap + settle of GarmentCode's shirt (1.5 cm edges) on mean_all with the packaged strokes.

    python benchmarks/bench_wrap.py [--repeat 5] [--settle global] [--polish-rounds 0] [--cli 6]

Prints the per-step timings of each run after a warm-up run (numba compilation, AABB trees) and the quality.
With --cli N, N runs of the warm `kitsuke dress` of the same files (a new process each, wall time) alternate with
N of the library's same call (`wrap(body, pattern, strokes)` from loaded objects: meshing, stroke resolution,
collider and report included) in this process, and the medians and their ratio are printed (target <= 1.5x).
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--settle", choices=["jacobi", "global"], default="jacobi", help="SettleSettings.method")
    ap.add_argument("--cli", type=int, default=0, metavar="N", help="time N warm `kitsuke dress` runs, and the library")
    ap.add_argument(
        "--polish-rounds", type=int, default=None, help="PolishSettings.rounds (default: the wrap's; 0: no polish)"
    )
    args = ap.parse_args()
    from kitsuke.body import load_body
    from kitsuke.cloth import BodyCollider
    from kitsuke.dressing import read_strokes, resolve_strokes
    from kitsuke.dressing.wrap import WrapParams, wrap
    from kitsuke.pattern import load_pattern, mesh_pattern

    body = load_body(ROOT / "tests/data/bodies/mean_all.obj")
    pattern = load_pattern(ROOT / "tests/data/pattern/shirt_mean_specification.json")
    strokes = read_strokes(ROOT / "src/kitsuke/assets/strokes/shirt_mean_all.json")
    pm = mesh_pattern(pattern, edge_length=1.5)
    collider = BodyCollider.from_body(body)
    resolved = resolve_strokes(strokes, pattern, collider.surface, pattern_mesh=pm)
    params = WrapParams()
    if args.settle == "global":
        params = params.changed({"settle.method": "global", "settle.iterations": 30})
    if args.polish_rounds is not None:
        params = params.changed({"polish.rounds": args.polish_rounds})
    wrap(body, pm, resolved, collider=collider, params=params, report=False)  # warm-up
    walls = []
    for _ in range(args.repeat):
        t = time.perf_counter()
        g = wrap(body, pm, resolved, collider=collider, params=params, report=False)
        walls.append(time.perf_counter() - t)
        print("  ".join(f"{k} {v * 1e3:.0f} ms" for k, v in g.timings.items()))
    print(
        f"shirt {pm.n_vertices} pattern vertices, {g.n_vertices} garment vertices, {len(g.faces)} faces, "
        f"{g.rings} rings"
    )
    print(
        f"wrap + settle (meshed pattern, resolved strokes, collider given): median {np.median(walls):.3f} s, "
        f"min {min(walls):.3f} s over {args.repeat} runs"
    )
    t = time.perf_counter()
    g = wrap(body, pattern, strokes, params=params)
    print(
        f"from files' objects (meshing, stroke resolution, collider, report included): {time.perf_counter() - t:.3f} s"
    )
    r = g.report
    print(
        f"quality: penetration {r.penetration_count} (deepest {r.penetration_deepest_mm:.1f} mm), strain mean "
        f"{100 * r.strain_mean:.1f} % max {100 * r.strain_max:.2f} %, seam gap {r.seam_gap_mm} mm, inverted "
        f"{r.inverted_count}, stroke residual max {1e3 * g.max_stroke_residual_m:.0f} mm"
    )
    if args.cli:
        cli_against_library(args.cli, lambda: wrap(body, pattern, strokes))


def cli_against_library(n: int, library: Callable[[], object]) -> None:
    """Median wall time of `kitsuke dress` (the shirt, GLB only) and of `library`, alternated n times."""
    with tempfile.TemporaryDirectory() as tmp:
        command = [
            str(Path(sys.executable).with_name("kitsuke")),
            "dress",
            "--body",
            str(ROOT / "tests/data/bodies/mean_all.obj"),
            "--pattern",
            str(ROOT / "tests/data/pattern/shirt_mean_specification.json"),
            "--strokes",
            str(ROOT / "src/kitsuke/assets/strokes/shirt_mean_all.json"),
            "-o",
            str(Path(tmp) / "shirt.glb"),
        ]
        subprocess.run(command, check=True, capture_output=True)  # numba's cache and the .pyc files filled
        cli, lib = [], []
        for _ in range(n):
            t = time.perf_counter()
            subprocess.run(command, check=True, capture_output=True)
            cli.append(time.perf_counter() - t)
            t = time.perf_counter()
            library()
            lib.append(time.perf_counter() - t)
    c, w = float(np.median(cli)), float(np.median(lib))
    print(
        f"warm `kitsuke dress`: median {c:.2f} s ({min(cli):.2f}-{max(cli):.2f}); the library's same call: median "
        f"{w:.2f} s ({min(lib):.2f}-{max(lib):.2f}); ratio {c / w:.2f}x (target <= 1.5x)"
    )


if __name__ == "__main__":
    main()
