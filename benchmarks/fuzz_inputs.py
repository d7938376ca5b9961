"""Fuzz every reader: N mutated files per input format, each must end in success or one line of InputError that
names the file, within 10 s and 2 GB (issue 30).

    python benchmarks/fuzz_inputs.py [--n 10000] [--only body-obj bvh] [--jobs 2] [--seed 0] [--keep DIR]
        [--json out.json]

The cases are the tests' (tests/fuzz): hypothesis draws structure-aware mutations (JSON trees: NaN, inf, 10^400,
wrong types, missing and extra keys, duplicated or cut lists; text formats: nasty numbers, deleted, repeated and
swapped lines, cuts) and raw byte mutations of the seed files, without shrinking. Each case runs in a guarded
worker process (`tests.fuzz.harness.Worker`). Prints per reader the counts by outcome, the slowest case, and
each distinct finding once; `--keep DIR` writes the files of the findings there.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from tests.fuzz.harness import TARGETS, Worker  # noqa: E402


def fuzz_target(target: str, n: int, keep: str | None, seed: int) -> dict:
    from hypothesis import HealthCheck, Phase, given, settings
    from hypothesis import seed as hypothesis_seed
    from tests.fuzz.strategies import cases

    worker = Worker()
    counts: dict[str, int] = {}
    findings: dict[str, int] = {}
    slowest = 0.0
    t0 = time.perf_counter()

    @settings(
        max_examples=n,
        deadline=None,
        database=None,
        phases=[Phase.generate],
        suppress_health_check=list(HealthCheck),
    )
    @hypothesis_seed(seed)
    @given(data=cases(target))
    def run(data: bytes) -> None:
        nonlocal slowest
        outcome = worker.run(target, data)
        counts[outcome.status] = counts.get(outcome.status, 0) + 1
        slowest = max(slowest, outcome.seconds)
        if not outcome.fine:
            key = f"{outcome.status}: {outcome.detail[:200]}"
            if key not in findings and keep:
                folder = Path(keep)
                folder.mkdir(parents=True, exist_ok=True)
                (folder / f"{target}-{len(findings):03d}{TARGETS[target].suffix}").write_bytes(data)
            findings[key] = findings.get(key, 0) + 1

    try:
        run()
    finally:
        worker.close()
    return {
        "target": target,
        "cases": sum(counts.values()),
        "counts": counts,
        "findings": findings,
        "slowest_s": round(slowest, 3),
        "seconds": round(time.perf_counter() - t0, 1),
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--n", type=int, default=10_000, help="cases per reader (default 10,000)")
    ap.add_argument("--only", nargs="+", choices=sorted(TARGETS), help="these readers only")
    ap.add_argument("--jobs", type=int, default=2, help="readers fuzzed at once (default 2)")
    ap.add_argument("--seed", type=int, default=0, help="hypothesis seed (default 0): the same cases each run")
    ap.add_argument("--keep", help="write the files of the findings to this folder")
    ap.add_argument("--json", help="write the results as JSON")
    args = ap.parse_args()
    targets = args.only or sorted(TARGETS)
    with ProcessPoolExecutor(max_workers=args.jobs) as pool:
        futures = [pool.submit(fuzz_target, t, args.n, args.keep, args.seed) for t in targets]
        results = []
        for f in futures:
            r = f.result()
            results.append(r)
            c = r["counts"]
            bad = r["cases"] - c.get("ok", 0) - c.get("input-error", 0)
            print(
                f"{r['target']:20s} {r['cases']:6d} cases  ok {c.get('ok', 0):6d}  input-error "
                f"{c.get('input-error', 0):6d}  findings {bad:4d}  slowest {r['slowest_s']:6.2f} s  "
                f"({r['seconds']:.0f} s)",
                flush=True,
            )
            for k, count in sorted(r["findings"].items(), key=lambda kv: -kv[1]):
                print(f"    {count:5d}  {k}", flush=True)
    total = sum(r["cases"] for r in results)
    findings = sum(sum(r["findings"].values()) for r in results)
    print(f"total: {total} cases, {findings} findings (crashes, bad errors, hangs, memory)")
    if args.json:
        Path(args.json).write_text(json.dumps(results, indent=1) + "\n")


if __name__ == "__main__":
    main()
