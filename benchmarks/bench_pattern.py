"""Timings of the pattern layer: imports, kimono generation, triangulation, pictures.

Run from the repository root:  python benchmarks/bench_pattern.py
Prints one line per measurement (median of repeated runs, after one warm-up) and a JSON summary at the end.
"""

from __future__ import annotations

import json
import platform
import statistics
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT / "tests" / "data" / "pattern"


def timed(fn, repeat: int = 7):
    fn()  # warm-up: imports, caches
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), out


def main() -> None:
    from kitsuke.pattern import (
        kimono_texture,
        load_pattern,
        make_kimono,
        mesh_pattern,
        mesh_quality,
        render_pattern_png,
        render_pattern_svg,
    )

    results = {}

    def report(key, seconds, extra=""):
        results[key] = {"ms": round(seconds * 1e3, 2)}
        print(f"{key:40s} {seconds * 1e3:9.2f} ms  {extra}")

    for name in ("shirt_mean_specification.json", "hoody_mean_specification.json"):
        t, p = timed(lambda name=name: load_pattern(DATA / name))
        report(f"import GarmentCode {name.split('_')[0]}", t, f"{len(p.pieces)} pieces, {len(p.seams)} seams")
    t, p = timed(lambda: load_pattern(DATA / "teagan_tshirt_cisMaleAdult42.svg"))
    report("import SVG teagan t-shirt", t, f"{len(p.pieces)} pieces")
    t, k = timed(make_kimono)
    report("generate kimono (standard size)", t, f"{len(k.pieces)} pieces, {len(k.seams)} seams")

    shirt = load_pattern(DATA / "shirt_mean_specification.json")
    for label, pattern in (("shirt", shirt), ("kimono", k)):
        for h in (1.5, 1.0):
            t, m = timed(lambda pattern=pattern, h=h: mesh_pattern(pattern, edge_length=h), repeat=5)
            q = mesh_quality(m)
            report(
                f"triangulate {label} at {h} cm",
                t,
                f"{m.n_vertices} vertices, {m.n_faces} triangles, min angle {q['min_angle_deg']:.1f}°, "
                f"{q['interior_within_30pct']:.1%} interior edges within 30 %",
            )
            results[f"triangulate {label} at {h} cm"].update(vertices=m.n_vertices, triangles=m.n_faces)

    t, _ = timed(lambda: render_pattern_svg(shirt), repeat=3)
    report("SVG picture shirt", t)
    t, _ = timed(lambda: render_pattern_png(shirt, max_px=2400), repeat=3)
    report("PNG picture shirt (2400 px)", t)
    t, _ = timed(lambda: render_pattern_png(k, max_px=2400, texture="asanoha"), repeat=3)
    report("PNG picture kimono textured (2400 px)", t)
    t, img = timed(lambda: kimono_texture(motif="asanoha", px_per_cm=64), repeat=5)
    report("asanoha tile (64 px/cm)", t, f"{img.shape[1]}x{img.shape[0]} px")
    print(
        json.dumps(
            {
                "machine": platform.processor() or platform.machine(),
                "python": platform.python_version(),
                "results": results,
            },
            indent=1,
        )
    )


if __name__ == "__main__":
    main()
