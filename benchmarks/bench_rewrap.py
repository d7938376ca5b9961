"""Benchmark: re-wrap of the demo's kimono, its hem turned up by a stroke drawn on the garment, pins at the chest.

    python benchmarks/bench_rewrap.py [--lift-cm 4 10] [--repeat 3]

The kimono is `dress_default_kimono()` (1.5 cm edges, as `kitsuke demo` dresses it). Its left front's pattern
row 8 cm above the hem is sent, by one garment stroke, to where the row `--lift-cm` higher lies now; every 40th
vertex above 1 m is pinned (the case `tests/dressing/test_rewrap.py` checks). Printed per lift: the re-wrap's
time by stage (medians over `--repeat` runs after a warm-up) and its quality: mean / max strain, the stroke's
residual, the pins' largest move, inverted triangles.
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np


def hem_lift(garment, dy_cm: float, piece: str = "migoro_left"):
    """Garment strokes turning up `piece`'s hem: its pattern row 8 cm above the hem to where the row dy_cm higher
    is now on the garment."""
    from kitsuke.dressing import BodyStroke, PatternStroke, StrokePair, Strokes
    from kitsuke.dressing._place import locate_in_triangles

    row = np.array([[4.0, 8.0], [26.0, 8.0]])
    k = garment.piece_names.index(piece)
    f0, f1 = garment.piece_faces[k]
    faces, bary = locate_in_triangles(garment.corner_uv[f0:f1] * 100.0, np.arange(f0, f1), row + [0.0, dy_cm])
    on = np.einsum("ij,ijk->ik", bary, garment.positions[garment.faces[faces]])
    return Strokes(
        [StrokePair(1, PatternStroke(piece, row.tolist()), BodyStroke(points=on.tolist()))], target="garment"
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--lift-cm", type=float, nargs="+", default=[4.0, 10.0])
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()

    from kitsuke.body import default_body
    from kitsuke.cloth import BodyCollider
    from kitsuke.dressing.export import as_garment_file
    from kitsuke.dressing.kimono import dress_default_kimono
    from kitsuke.dressing.rewrap import rewrap

    body = default_body()
    collider = BodyCollider.from_body(body)
    garment = as_garment_file(dress_default_kimono(body))
    pins = garment.positions[garment.positions[:, 1] > 1.0][::40]
    print(f"kimono: {len(garment.positions)} vertices, {len(pins)} pins")
    for lift in args.lift_cm:
        strokes = hem_lift(garment, lift)
        rewrap(body, garment, strokes, pins=pins, collider=collider)  # warm-up: compilation, caches
        runs = []
        for _ in range(args.repeat):
            t0 = time.perf_counter()
            r = rewrap(body, garment, strokes, pins=pins, collider=collider)
            runs.append((time.perf_counter() - t0, r))
        total = statistics.median(t for t, _ in runs)
        stages = {k: statistics.median(r.timings.get(k, 0.0) for _, r in runs) for k in runs[0][1].timings}
        shown = ", ".join(f"{k} {v:.2f}" for k, v in stages.items() if k not in ("relax", "rewrap"))
        r = runs[-1][1]
        q = r.report
        pinned_move = float(r.moved_m[r.pinned].max()) if r.pinned.any() else 0.0
        print(f"lift {lift:g} cm: {total:.2f} s median of {args.repeat} ({shown})")
        print(
            f"  strain mean {100 * q.strain_mean:.2f} % max {100 * q.strain_max:.1f} %, stroke residual "
            f"{1e3 * r.stroke_residual_m.max():.1f} mm, pins moved {1e3 * pinned_move:.3f} mm, "
            f"inverted {q.inverted_count}, deepest {q.penetration_deepest_mm:.1f} mm"
        )


if __name__ == "__main__":
    main()
