"""Cloth core benchmarks: relaxation iterations per second on a 5k-vertex cloth around the default body, the
collision update, the quality measures and the subdivision.

    python benchmarks/bench_cloth.py            # numba kernels as shipped (parallel=True)
    python benchmarks/bench_cloth.py --serial   # also recompile the kernels with parallel=False and compare

The cloth is a tube hugging the default body from the knees (0.35 m) to the waist (0.92 m): 72 x 70 = 5,040
vertices, 9,936 triangles, ~1.5 cm edges around and 0.8 cm up, its top ring pinned; it settles under gravity
against the body and the capsules. Every figure is the best of several runs after warm-up (numba compiled):
this machine's neighbours make single runs vary by up to 10x, and the best run is the reproducible one.
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np
from _timing import timeit as _timeit

from kitsuke.body import default_body
from kitsuke.cloth import (
    BodyCollider,
    ClothModel,
    ClothState,
    collide,
    colliding_edges,
    hugging_tube,
    locality_order,
    refine,
    relax,
    restore_lengths,
    track,
)
from kitsuke.metrics import penetration, quality_report


def timeit(fn, repeat: int = 7) -> float:
    """Best of `repeat` calls (this host is noisy), seconds."""
    return _timeit(fn, repeat, stat="min")


def setup(body, shuffle: bool = False, reorder: bool = False):
    pos, faces, rc = hugging_tube(body.mesh.vertices, 0.35, 0.92, 72, 70, centre_xz=(0.0, 0.015))
    pinned = np.arange(len(pos)) >= len(pos) - 72
    if shuffle:  # the same cloth with its vertices and faces in random order: poor memory locality
        rng = np.random.default_rng(0)
        perm = rng.permutation(len(pos))
        inv = np.argsort(perm)
        pos, pinned, faces = pos[perm], pinned[perm], inv[faces]
        order = rng.permutation(len(faces))
        faces, rc = faces[order], rc[order]
    if reorder:  # back to a good order, the way a pattern mesh should be prepared
        vorder, forder = locality_order(faces, len(pos))
        rank = np.argsort(vorder)
        pos, pinned, faces, rc = pos[vorder], pinned[vorder], rank[faces[forder]], rc[forder]
    model = ClothModel.from_corners(faces, rc)
    return model, ClothState.new(model, pos, pinned=pinned)


def iterations_per_second(model, state, collider, n: int = 50) -> float:
    return n / timeit(lambda: relax(model, state, collider, iterations=n), repeat=9)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--serial", action="store_true", help="also time the kernels compiled with parallel=False")
    args = ap.parse_args()
    body = default_body()
    print(f"numba threads: {os.environ.get('NUMBA_NUM_THREADS', 'default')} ({os.cpu_count()} CPUs)")
    t0 = time.perf_counter()
    collider = BodyCollider.from_body(body)
    print(f"BodyCollider.from_body (13,380 vertices, 10 capsules)        {(time.perf_counter() - t0) * 1e3:8.1f} ms")
    model, state = setup(body)
    print(f"cloth: {model.n_vertices} vertices, {model.n_faces} triangles, {len(model.hinges)} hinges")
    t = timeit(lambda: setup(body), repeat=3)
    print(f"ClothModel + ClothState build                                {t * 1e3:8.1f} ms")
    relax(model, state, collider, iterations=100)  # compile and settle

    ips = iterations_per_second(model, state, collider)
    print(f"relax with collision (body + capsules)                       {ips:8.0f} it/s  ({1e3 / ips:.2f} ms)")
    ips0 = iterations_per_second(model, state, None)
    print(f"relax without collision                                      {ips0:8.0f} it/s  ({1e3 / ips0:.2f} ms)")
    t = timeit(lambda: restore_lengths(model, state, None, sweeps=30), repeat=7) / 30
    print(f"restore_lengths sweep (Gauss-Seidel over every edge)         {t * 1e3:8.2f} ms")
    t = timeit(lambda: restore_lengths(model, state, collider, sweeps=30), repeat=7) / 30
    print(f"restore_lengths sweep, collision every 3rd (the wrap's)      {t * 1e3:8.2f} ms")
    t = timeit(lambda: collide(model, state, collider), repeat=20)
    print(f"collide (capsules, tracking walk, push-out)                  {t * 1e3:8.2f} ms")
    t = timeit(lambda: track(model, state, collider), repeat=20)
    print(f"track (incremental walk only)                                {t * 1e3:8.2f} ms")

    def fresh_track():
        state.contacts.face[:] = -1
        track(model, state, collider)

    t = timeit(fresh_track, repeat=5)
    print(f"track from scratch (global AABB search, all vertices)        {t * 1e3:8.2f} ms")
    t = timeit(lambda: penetration(state.positions, body.mesh), repeat=5)
    print(f"metrics.penetration (winding number + AABB)                  {t * 1e3:8.2f} ms")
    t = timeit(
        lambda: quality_report(
            state.positions, model.faces, body.mesh, rest_lengths=model.rest_lengths, rest_areas=model.rest_areas
        ),
        repeat=5,
    )
    print(f"metrics.quality_report (all measures)                        {t * 1e3:8.2f} ms")
    fires = colliding_edges(model, state)
    t = timeit(lambda: colliding_edges(model, state), repeat=20)
    print(f"colliding_edges (paper's edge test, {int(fires.sum())} fire)                  {t * 1e3:8.2f} ms")
    new_model, _, r = refine(model, state.copy(), collider)
    t = timeit(lambda: refine(model, state.copy(), collider), repeat=5)
    print(
        f"refine (edge test + adaptive sqrt3, {int(r.split.sum())} faces split)        {t * 1e3:8.2f} ms "
        f"-> {new_model.n_vertices} vertices"
    )

    sm, ss = setup(body, shuffle=True)
    relax(sm, ss, collider, iterations=100)
    ips_s = iterations_per_second(sm, ss, collider)
    print(f"relax with collision, vertices/faces in random order         {ips_s:8.0f} it/s")
    sm, ss = setup(body, shuffle=True, reorder=True)
    relax(sm, ss, collider, iterations=100)
    ips_r = iterations_per_second(sm, ss, collider)
    print(f"relax with collision, random order then locality_order       {ips_r:8.0f} it/s")

    if args.serial:
        from kitsuke.cloth import _collide_kernels, _kernels

        _kernels.set_parallel(False)
        _collide_kernels.set_parallel(False)
        relax(model, state, collider, iterations=5)  # compile
        ips1 = iterations_per_second(model, state, collider)
        print(f"relax with collision, kernels parallel=False                 {ips1:8.0f} it/s")
        ips1 = iterations_per_second(model, state, None)
        print(f"relax without collision, kernels parallel=False              {ips1:8.0f} it/s")


if __name__ == "__main__":
    main()
