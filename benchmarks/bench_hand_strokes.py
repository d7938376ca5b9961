"""The shipped shirt strokes changed as a hand would change them: does the wrap still dress the shirt?

    python benchmarks/bench_hand_strokes.py

GarmentCode's shirt on its mean_all body with `shirt_mean_all` strokes, and seven changes of them (each body
stroke changed on the surface, the pattern strokes as shipped): one stroke 10 % and 30 % shorter than its pattern
stroke, every body stroke moved 2 cm down or slid 2 cm along itself, no strokes on one sleeve, only the two front
strokes, every body stroke drawn the other way. Prints per case the outcome (written within the targets, written
out of them, or failed: exit 1 in `kitsuke dress`), the quality and the wrap time.
"""

from __future__ import annotations

import dataclasses
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    from kitsuke.body import load_body
    from kitsuke.cloth import BodyCollider
    from kitsuke.dressing import BodyStroke, load_packaged_strokes, target_misses, wrap
    from kitsuke.dressing.perturb import scale_polyline
    from kitsuke.errors import ComputationError
    from kitsuke.pattern import load_pattern

    body = load_body(ROOT / "tests/data/bodies/mean_all.obj")
    pattern = load_pattern(ROOT / "tests/data/pattern/shirt_mean_specification.json")
    collider = BodyCollider.from_body(body)
    surface = collider.surface_for(body.mesh)
    shipped = load_packaged_strokes("shirt_mean_all")

    def changed(fn, ids=None):
        pairs = []
        for p in shipped.pairs:
            if ids is not None and p.id not in ids:
                pairs.append(p)
                continue
            pts = fn(np.asarray(p.body.points, dtype=np.float64))
            if pts is not None:
                pairs.append(dataclasses.replace(p, body=BodyStroke(points=surface.closest(pts).points)))
        return dataclasses.replace(shipped, pairs=pairs)

    def slide(pts, by=0.02):
        d = pts[-1] - pts[0]
        return pts + by * d / np.linalg.norm(d)

    cases = {
        "as shipped": shipped,
        "stroke 1 10 % shorter": changed(lambda p: scale_polyline(p, 0.9), {1}),
        "stroke 1 30 % shorter": changed(lambda p: scale_polyline(p, 0.7), {1}),
        "every stroke 2 cm down": changed(lambda p: p - [0.0, 0.02, 0.0]),
        "every stroke slid 2 cm along itself": changed(slide),
        "no strokes on the left sleeve": dataclasses.replace(
            shipped, pairs=[p for p in shipped.pairs if "left_sleeve" not in p.pattern.piece]
        ),
        "only the two front strokes": dataclasses.replace(
            shipped, pairs=[p for p in shipped.pairs if "ftorso" in p.pattern.piece]
        ),
        "every stroke drawn the other way": changed(lambda p: p[::-1]),
    }
    wrap(body, pattern, shipped, collider=collider)  # warm-up (numba, caches)
    print(f"{'change':38s} {'outcome':14s} {'mean':>7s} {'max':>7s} {'stroke':>8s} {'time':>6s}")
    for name, strokes in cases.items():
        t0 = time.perf_counter()
        try:
            g = wrap(body, pattern, strokes, collider=collider)
        except ComputationError as e:
            print(f"{name:38s} {'failed':14s} {'':>7s} {'':>7s} {'':>8s} {time.perf_counter() - t0:5.1f}s  {e}")
            continue
        r = g.report
        outcome = "within targets" if not target_misses(g) else "out of target"
        print(
            f"{name:38s} {outcome:14s} {100 * r.strain_mean:6.2f}% {100 * r.strain_max:6.1f}% "
            f"{1e3 * g.max_stroke_residual_m:6.1f}mm {g.timings['wrap']:5.1f}s  {'; '.join(target_misses(g))[:90]}"
        )


if __name__ == "__main__":
    main()
