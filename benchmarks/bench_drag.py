"""Benchmark: dragging a ~5k-vertex garment along the default body (issue 4: one update <= 33 ms).

    python benchmarks/bench_drag.py [--garment kimono|tshirt] [--edge-length CM] [--updates 60] [--pinned]

The garment: the default kimono at 2.5 cm (5.3k vertices, sleeves hanging; dragged 10 cm up and down three times,
which tore its coarse hem round the shins before the drag's global steps held touching cloth on its contact
planes: the quality line after the drag shows it) or the FreeSewing T-shirt with its
shipped strokes at 1.5 cm (the size its strokes are checked at, 4.6k vertices, clean).

One update = one mouse-move event: the drag spread over the garment (the body part's rigid motion, the feet
sliding along the body) plus the relaxation (one global step, two local iterations, collision). Printed: the
garment size, the time to open a session, grab (dependency graph, weights, factorisation), one update for
mouse-sized moves (2 mm) and drags-file-sized moves (1 cm), and the release; medians and minima over the updates
(the minimum is the figure least disturbed by other work on a shared machine). --pinned also runs scenario (c) of
tests/dressing/test_drag.py on the kimono: its back seam pinned, its front lifted 6 cm, the release timed (its
polish, and where the cloth is too taut held, the let-go point's give: `DragParams.release_give_m`).

On a 2-core machine with another process busy on one core, OpenMP threads that spin while they wait (numba's
"omp" layer; libgomp's default) make every update take ~190 ms instead of ~10; OMP_WAIT_POLICY=PASSIVE avoids it
(measured 14 ms under the same load). KITSUKE_NUMBA_PARALLEL=0 runs kitsuke's kernels single-threaded.
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--garment", choices=["kimono", "tshirt"], default="kimono", help="what to drag (default kimono)")
    ap.add_argument(
        "--edge-length", type=float, default=None, help="triangle edge length, cm (default: kimono 2.5, T-shirt 1.5)"
    )
    ap.add_argument("--updates", type=int, default=60, help="updates timed per move size (default 60)")
    ap.add_argument(
        "--pinned",
        action="store_true",
        help="also time scenario (c) on the kimono: the back seam pinned, the front lifted 6 cm, released",
    )
    args = ap.parse_args()
    if args.pinned and args.garment != "kimono":
        ap.error("--pinned pins the kimono's back seam: use it with --garment kimono")
    from kitsuke.body import default_body
    from kitsuke.cloth import BodyCollider
    from kitsuke.dressing import WrapParams
    from kitsuke.dressing.drag import DragSession
    from kitsuke.dressing.kimono import dress_default_kimono

    body = default_body()
    collider = BodyCollider.from_body(body)
    if args.garment == "kimono":
        garment = dress_default_kimono(body, params=WrapParams(edge_length_cm=args.edge_length or 2.5))
    else:
        from pathlib import Path

        from kitsuke.dressing import load_packaged_strokes, wrap
        from kitsuke.pattern import load_pattern

        data = Path(__file__).resolve().parents[1] / "tests" / "data" / "pattern"
        pattern = load_pattern(data / "teagan_tshirt_cisMaleAdult42_sewn.json")
        params = WrapParams(edge_length_cm=args.edge_length or 1.5)
        garment = wrap(body, pattern, load_packaged_strokes("tshirt_default"), params=params, collider=collider)
    r0 = garment.report
    print(
        f"dressed: strain mean {100 * r0.strain_mean:.2f} % max {100 * r0.strain_max:.2f} %, "
        f"inverted {r0.inverted_count}, penetration {r0.penetration_count}"
    )
    print(
        f"{args.garment} {garment.n_vertices} vertices, {len(garment.faces)} faces; numba threads: "
        f"{'off' if os.environ.get('KITSUKE_NUMBA_PARALLEL') == '0' else 'on'} ({os.cpu_count()} cores), "
        f"OMP_WAIT_POLICY={os.environ.get('OMP_WAIT_POLICY', '(default)')}"
    )
    DragSession(body, garment, collider=collider).grab(vertex=0)  # warm-up: numba compilation, caches
    t = time.perf_counter()
    session = DragSession(body, garment, collider=collider)
    t_open = time.perf_counter() - t
    x = session.positions
    front = int(np.argmax(x[:, 2] - 5 * np.abs(x[:, 0]) - 5 * np.abs(x[:, 1] - 1.1)))
    t = time.perf_counter()
    session.grab(vertex=front)
    t_grab = time.perf_counter() - t
    print(f"open session {1e3 * t_open:.0f} ms, grab {1e3 * t_grab:.0f} ms")
    for step_m in (0.002, 0.01):
        times = []
        for k in range(args.updates):
            up = 1.0 if (k // 10) % 2 == 0 else -1.0  # up and down, so the garment stays on the body
            t = time.perf_counter()
            session.update(np.array([0.0, up * step_m, 0.0]))
            times.append(time.perf_counter() - t)
        times_ms = 1e3 * np.array(times)
        print(
            f"update, {1e3 * step_m:.0f} mm moves: median {np.median(times_ms):.1f} ms, min {times_ms.min():.1f} ms, "
            f"90th percentile {np.percentile(times_ms, 90):.1f} ms ({1e3 / np.median(times_ms):.0f} updates/s)"
        )
    released = session.release()
    print(release_line(released))
    print(quality_line(f"after {2 * args.updates} updates", session.report()))
    if args.pinned:
        pinned_front_lift(body, garment, collider)


def release_line(r) -> str:
    return (
        f"release {1e3 * r.seconds:.0f} ms (polished: {r.polished}, {r.new_vertices} new vertices, the let-go point "
        f"gave {100 * r.grab_gave_m:.2f} cm)"
    )


def quality_line(when: str, r) -> str:
    return (
        f"quality {when}: penetration {r.penetration_count}, strain mean {100 * r.strain_mean:.2f} % max "
        f"{100 * r.strain_max:.2f} %, inverted {r.inverted_count}"
    )


def pinned_front_lift(body, garment, collider) -> None:
    """Scenario (c) of tests/dressing/test_drag.py: pins down the kimono's back seam, its outer front lifted 6 cm
    in three 2 cm moves, released (where the let-go point may give: `DragParams.release_give_m`)."""
    from kitsuke.dressing.drag import DragSession

    session = DragSession(body, garment, collider=collider)
    x = session.positions
    faces = {n: np.unique(garment.faces[a:b]) for n, (a, b) in zip(garment.piece_names, garment.piece_faces)}
    session.pin(vertices=np.intersect1d(faces["migoro_left"], faces["migoro_right"]))
    near = np.flatnonzero(np.hypot(x[:, 0], x[:, 1] - 1.1) < 0.015)
    outer = near[x[near, 2] > x[near, 2].max() - 0.003]
    session.grab(vertex=int(outer[np.argmin(np.hypot(x[outer, 0], x[outer, 1] - 1.1))]))
    ups = [t for _ in range(3) for t in session.move_by([0.0, 0.02, 0.0]).update_seconds]
    print(f"pinned front lift 6 cm: {len(ups)} updates, median {1e3 * np.median(ups):.1f} ms")
    print(release_line(session.release()))
    print(quality_line("after the pinned lift", session.report()))


if __name__ == "__main__":
    main()
