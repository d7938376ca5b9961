"""Throughput of `kitsuke batch dress` on random GarmentCode designs with 1 and 2 workers, its scaling, and what
the runners cost beyond the jobs.

    python benchmarks/bench_batch.py --seed 101 --n 12 [--runners local ray] [--workers 1 2] [--keep DIR]

- Corpus: the designs of bench_corpus.py (`sample`, the same seed and sampler), each dressed as bench_corpus
  dresses it (suggested strokes, perturbed with the same seed, robust targets) through `run_batch`. For each
  runner and worker count: the wall time of the whole batch (start-up and warm-up included), jobs per minute,
  the jobs' own mean time, and the workers' busy share (the jobs' summed time over workers x wall time).
  Scaling efficiency = jobs/min with 2 workers / (2 x jobs/min with 1).
- Scheduling overhead: jobs that only sleep (`_sleep_kind.py`; one shared 1 MB input, a 10 kB output file each),
  batches of 20 and 20 + `--sleep-jobs` jobs of `--sleep` seconds: the second's extra wall time beyond the extra
  sleep, per job, is what scheduling, transfers and the job folders cost a worker, given as a share of a 10 s
  job; start-up = the first batch's wall time beyond its sleep (the workers' start and warm-up) and, for Ray, its
  own start (one Ray for both batches).
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
from pathlib import Path

import _sleep_kind
from bench_corpus import SAMPLER, batch_jobs, sample


def runner_of(name: str, workers: int):
    from kitsuke.batch import LocalRunner, RayRunner

    return (LocalRunner if name == "local" else RayRunner)(workers=workers, timeout_s=600)


def corpus(name: str, workers: int, jobs: list, tmp: Path) -> dict:
    from kitsuke.batch import DressKind, run_batch

    t0 = time.perf_counter()
    result = run_batch(DressKind(), jobs, tmp / f"corpus-{name}-{workers}", runner_of(name, workers), progress=False)
    wall = time.perf_counter() - t0
    records = json.loads(result.summary_json.read_text())["jobs"]
    busy = sum(r["seconds"] for r in records)
    return {
        "wall_s": wall,
        "jobs_per_min": 60 * len(jobs) / wall,
        "mean_job_s": busy / len(jobs),
        "busy_share": busy / (workers * wall),
        "statuses": [r["status"] for r in records],
    }


def overhead(name: str, workers: int, n: int, seconds: float, tmp: Path) -> dict:
    """Two batches of sleeping jobs, SMALL and SMALL + n: the difference of their wall times beyond n x seconds /
    workers is what n jobs cost the runner (start-up, the same in both, cancels out)."""
    from kitsuke.batch import run_batch

    ray_start = 0.0
    if name == "ray":
        import logging

        import ray
        import ray.cloudpickle

        ray.cloudpickle.register_pickle_by_value(_sleep_kind)  # Ray's workers do not see this folder
        # One Ray for both batches: its own start (seconds, and varying by seconds) would swamp the difference.
        t0 = time.perf_counter()
        ray.init(address="local", num_cpus=workers, include_dashboard=False, logging_level=logging.WARNING)
        ray_start = time.perf_counter() - t0
    walls = []
    try:
        for size in (SMALL, SMALL + n):
            jobs = [_sleep_kind.SleepJob(f"s{k}", seconds) for k in range(size)]
            t0 = time.perf_counter()
            run_batch(_sleep_kind.SleepKind(), jobs, tmp / f"sleep-{name}-{workers}-{size}",
                      runner_of(name, workers), progress=False)  # fmt: skip
            walls.append(time.perf_counter() - t0)
    finally:
        if name == "ray":
            ray.shutdown()
    per_job = (walls[1] - walls[0] - n * seconds / workers) * workers / n
    start = ray_start + walls[0] - SMALL * seconds / workers
    return {"start_s": start, "wall_s": walls[1], "overhead_per_job_ms": 1e3 * per_job, "share_of_10s": per_job / 10}


#: Jobs of the smaller overhead batch.
SMALL = 20


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seed", type=int, default=101)
    ap.add_argument("--n", type=int, default=12, help="designs sampled")
    ap.add_argument("--keep", help="keep the sampled designs in this folder (reused when already there)")
    ap.add_argument("--sampler", type=Path, default=SAMPLER)
    ap.add_argument("--runners", nargs="+", default=["local", "ray"], choices=["local", "ray"])
    ap.add_argument("--workers", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--no-corpus", action="store_true", help="only the scheduling overhead")
    ap.add_argument("--sleep-jobs", type=int, default=200)
    ap.add_argument("--sleep", type=float, default=0.1, help="seconds each overhead job sleeps")
    args = ap.parse_args()

    with tempfile.TemporaryDirectory() as tmpname:
        tmp = Path(tmpname)
        folder = (Path(args.keep) if args.keep else tmp) / f"seed{args.seed}"
        paths = [] if args.no_corpus else sorted(folder.glob("*_specification.json"))
        if not args.no_corpus and not paths:
            paths = sample(args.seed, args.n, folder, args.sampler)
        jobs = batch_jobs(paths, perturb=True)
        for name in args.runners:
            rates = {}
            for w in args.workers:
                o = overhead(name, w, args.sleep_jobs, args.sleep, tmp)
                print(
                    f"{name:5s} {w} worker(s): start-up {o['start_s']:.1f} s; {args.sleep_jobs} more jobs of "
                    f"{args.sleep:g} s: {o['overhead_per_job_ms']:.1f} ms per job beyond their sleep = "
                    f"{100 * o['share_of_10s']:.3f} % of a 10 s job",
                    flush=True,
                )
                if not jobs:
                    continue
                c = corpus(name, w, jobs, tmp)
                rates[w] = c["jobs_per_min"]
                classes = ", ".join(f"{s} {c['statuses'].count(s)}" for s in sorted(set(c["statuses"])))
                print(
                    f"{name:5s} {w} worker(s): {len(jobs)} designs in {c['wall_s']:.1f} s = {c['jobs_per_min']:.2f} "
                    f"jobs/min; mean job {c['mean_job_s']:.1f} s; workers busy {100 * c['busy_share']:.0f} %; "
                    f"{classes}",
                    flush=True,
                )
            if 1 in rates and len(rates) > 1:
                for w, r in rates.items():
                    if w > 1:
                        print(f"{name:5s} scaling efficiency 1 -> {w} workers: {100 * r / (w * rates[1]):.0f} %")


if __name__ == "__main__":
    main()
