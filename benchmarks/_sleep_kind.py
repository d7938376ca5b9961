"""A batch job kind that only sleeps, for measuring what the batch runners cost beyond the jobs themselves
(bench_batch.py): its jobs need one shared input each, like a dress job's body, and return a small file."""

from __future__ import annotations

import time
from dataclasses import dataclass

from kitsuke.batch import OK, Outcome


@dataclass(frozen=True)
class SleepJob:
    id: str
    seconds: float
    where: str = ""

    def spec(self) -> dict:
        return {"id": self.id, "seconds": self.seconds}


@dataclass(frozen=True)
class SleepKind:
    name: str = "sleep"

    def inputs(self, job: SleepJob) -> dict:
        return {"body": "shared"}

    def load(self, key):
        return bytes(1_000_000)  # a megabyte, read once and sent once per worker

    def timeout_s(self, job: SleepJob):
        return None

    def warm(self) -> None:
        pass

    def run(self, job: SleepJob, inputs: dict, derived) -> Outcome:
        time.sleep(job.seconds)
        return Outcome(OK, files={"out.txt": b"x" * 10_000})
