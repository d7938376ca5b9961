"""Benchmark: strokes and surface queries on the default body (prints its figures).

    python benchmarks/bench_strokes.py

Figures: closest points (libigl AABB) for near and far points, laser casts (embree) first and last hit,
resolving the packaged kimono strokes (cold: building the AABB and the ray scene; warm: reusing a Surface),
triangles_crossed for a long stroke on the kimono mesh at 1.5 cm.
"""

from __future__ import annotations

import time

import numpy as np
from _timing import timeit

from kitsuke.body import default_body
from kitsuke.dressing import PatternStroke, load_packaged_strokes, resolve_strokes, triangles_crossed
from kitsuke.geometry.surface import Surface
from kitsuke.pattern import default_kimono, mesh_pattern


def main() -> None:
    body = default_body()
    pattern = default_kimono()
    pm = mesh_pattern(pattern, edge_length=1.5)
    strokes = load_packaged_strokes()
    rng = np.random.default_rng(0)
    print(f"default body: {body.mesh.n_vertices} vertices, {body.mesh.n_faces} faces")
    print(f"kimono mesh at 1.5 cm: {pm.n_faces} faces; packaged strokes: {len(strokes)} pairs")

    t = time.perf_counter()
    resolve_strokes(strokes, pattern, body.mesh, pattern_mesh=pm)
    cold = 1e3 * (time.perf_counter() - t)
    print(f"resolve packaged strokes, cold (AABB + embree scene built): {cold:.1f} ms")
    surf = Surface(body.mesh)
    resolve_strokes(strokes, pattern, surf, pattern_mesh=pm)
    ms = 1e3 * timeit(lambda: resolve_strokes(strokes, pattern, surf, pattern_mesh=pm), stat="min", warmup=False)
    print(f"resolve packaged strokes, warm Surface, with pattern-mesh checks: {ms:.1f} ms")
    ms = 1e3 * timeit(lambda: resolve_strokes(strokes, pattern, surf), stat="min", warmup=False)
    print(f"resolve packaged strokes, warm Surface, no pattern mesh: {ms:.1f} ms")

    v = body.mesh.vertices
    near = v[rng.integers(0, len(v), 10_000)] + rng.normal(scale=0.01, size=(10_000, 3))
    far = rng.normal(size=(10_000, 3)) * 5.0
    print(
        f"closest, 10k points within ~1 cm: {1e3 * timeit(lambda: surf.closest(near), stat='min', warmup=False):.1f} ms"
    )
    print(
        f"closest, 10k points metres away: {1e3 * timeit(lambda: surf.closest(far), stat='min', warmup=False):.1f} ms"
    )

    n = 100_000
    o = np.c_[rng.uniform(-0.2, 0.2, n), rng.uniform(0.9, 1.4, n), np.full(n, 2.0)]
    d = np.tile([0.0, 0.0, -1.0], (n, 1))
    ms = 1e3 * timeit(lambda: surf.cast(o, d), 3, stat="min", warmup=False)
    print(f"cast 100k rays through the torso, first hit: {ms:.0f} ms")
    ms = 1e3 * timeit(lambda: surf.cast(o, d, hit="last"), 3, stat="min", warmup=False)
    print(f"cast 100k rays through the torso, last hit: {ms:.0f} ms")

    y = np.linspace(170, 300, 200)
    stroke = PatternStroke("migoro_left", np.c_[15 + 5 * np.sin(y / 10), y])
    ms = 1e3 * timeit(lambda: triangles_crossed(pm, stroke), stat="min", warmup=False)
    print(
        f"triangles_crossed, 200-point stroke on a {pm.piece_faces[1, 1] - pm.piece_faces[1, 0]}-face piece: "
        f"{ms:.1f} ms ({len(triangles_crossed(pm, stroke))} faces)"
    )


if __name__ == "__main__":
    main()
