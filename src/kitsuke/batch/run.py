"""A whole batch: the jobs not yet finished in OUTDIR run on a runner, each written as it finishes, and the summary
written at the end (also when the batch is stopped: the jobs it did not reach are `not_run`)."""

from __future__ import annotations

import os
import sys
import time
from collections import Counter
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from .outcome import DONE, FAILED, OUT_OF_TARGET, REFUSED, JobKind, Outcome
from .outdir import LOGS, check_ids, finished, open_outdir, write_job
from .runners import Runner
from .summary import counts, summary_rows, write_summary


@dataclass
class BatchResult:
    """What a batch did. counts : jobs per status over the whole manifest (earlier runs included). ran : jobs run
    this time. skipped : jobs finished by an earlier run (--resume). summary_csv, summary_json : the tables."""

    counts: dict[str, int]
    ran: int
    skipped: int
    seconds: float
    summary_csv: Path
    summary_json: Path

    @property
    def unfinished(self) -> int:
        """Jobs that gave no outputs: refused, failed or not run."""
        return sum(n for status, n in self.counts.items() if status not in DONE)


def run_batch(
    kind: JobKind,
    jobs: list[Any],
    outdir: str | os.PathLike[str],
    runner: Runner,
    *,
    resume: bool = False,
    retry_failed: bool = False,
    progress: bool | None = None,
) -> BatchResult:
    """Run `jobs` (each with .id, .where and .spec()) of `kind` on `runner` into `outdir`.

    resume : run only the jobs OUTDIR has no finished folder for (without it, OUTDIR must be new or empty).
    retry_failed : with resume, run the failed jobs again too. progress : a bar on stderr (None: when stderr is a
    terminal; off a terminal with True or None, one line per finished job).
    """
    check_ids(jobs)
    out = open_outdir(outdir, resume=resume)
    records = finished(out, jobs, retry_failed=retry_failed) if resume else {}
    todo = [job for job in jobs if job.id not in records]
    runner.use_log_dir(out / LOGS)
    bar = Progress(len(jobs), list(records.values()), enabled=progress)
    bar.note(f"{len(todo)} jobs to run ({len(records)} finished before) on {runner.describe()}; workers warm up first")
    t0 = time.perf_counter()

    def on_outcome(job: Any, outcome: Outcome) -> None:
        records[job.id] = write_job(out, job, outcome)
        bar.update(records[job.id])

    try:
        runner.run(kind, todo, on_outcome)
    finally:
        bar.close()
        rows = summary_rows(jobs, records)
        csv_path, json_path = write_summary(out, rows)
    return BatchResult(counts(rows), len(todo), len(jobs) - len(todo), time.perf_counter() - t0, csv_path, json_path)


class Progress:
    """Jobs done, failed and remaining, and the ETA: a tqdm bar on a terminal; elsewhere (a log file) one line per
    finished job, with the same counts."""

    def __init__(self, total: int, before: list[dict[str, Any]], *, enabled: bool | None = None):
        self.total = total
        self.tally = Counter(r["status"] for r in before)
        self.lines = enabled is not False
        self.bar = None
        if enabled or (enabled is None and sys.stderr.isatty()):
            from tqdm import tqdm

            self.bar = tqdm(total=total, initial=len(before), desc="batch", unit="job", dynamic_ncols=True)
            self.bar.set_postfix_str(self._counts())

    def _counts(self) -> str:
        t = self.tally
        done = sum(t[s] for s in DONE)
        left = self.total - sum(t.values())
        return (
            f"done {done} (out of target {t[OUT_OF_TARGET]}), failed {t[FAILED]}, refused {t[REFUSED]}, "
            f"remaining {left}"
        )

    def note(self, text: str) -> None:
        """A line about the batch (off a terminal only: the bar says enough)."""
        if self.bar is None and self.lines:
            print(text, file=sys.stderr, flush=True)

    def update(self, record: dict[str, Any]) -> None:
        self.tally[record["status"]] += 1
        if self.bar is not None:
            self.bar.set_postfix_str(self._counts(), refresh=False)
            self.bar.update(1)
        elif self.lines:
            n = sum(self.tally.values())
            why = f": {record['reason']}" if record["status"] not in DONE and record["reason"] else ""
            print(
                f"[{n}/{self.total}] {record['id']}: {record['status']}{why} ({record['seconds']:.1f} s); "
                f"{self._counts()}",
                file=sys.stderr,
                flush=True,
            )

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()
