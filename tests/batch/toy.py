"""A job kind that does what a test tells it (succeed, raise, hang, kill its worker), for the runners' tests: the
runners must handle any JobKind, and these failures are hard to provoke with real garments."""

from __future__ import annotations

import os
import signal
import time
from dataclasses import dataclass, field

from kitsuke.batch import FAILED, OK, Outcome
from kitsuke.errors import InputError

#: Per worker process: warm-ups and jobs run there.
_WORKER = {"warmed": 0, "jobs": 0}


@dataclass(frozen=True)
class ToyJob:
    """action: "ok", "raise", "hang", "die" or "fail". word: its shared input ("bad" cannot be read)."""

    id: str
    action: str = "ok"
    word: str = "cloth"
    timeout_s: float | None = None
    where: str = ""

    def spec(self) -> dict:
        return {"id": self.id, "action": self.action, "word": self.word}


@dataclass
class ToyKind:
    name: str = "toy"
    loads: list = field(default_factory=list)  # driver side: every input read
    warm_fails: bool = False

    def inputs(self, job: ToyJob) -> dict:
        return {"word": ("word", job.word)}

    def load(self, key):
        self.loads.append(key)
        if key[1] == "bad":
            raise InputError("cannot read this word", key[1])
        return key[1].upper()

    def timeout_s(self, job: ToyJob):
        return job.timeout_s

    def warm(self) -> None:
        if self.warm_fails:
            raise RuntimeError("no kernels here")
        _WORKER["warmed"] += 1

    def run(self, job: ToyJob, inputs: dict, derived) -> Outcome:
        _WORKER["jobs"] += 1
        if job.action == "raise":
            raise ValueError(f"job {job.id} raised")
        if job.action == "hang":
            time.sleep(600)
        if job.action == "die":
            os.kill(os.getpid(), signal.SIGKILL)
        if job.action == "fail":
            return Outcome(FAILED, "a computation that gave nothing")
        length = derived("word", len)
        measures = {"word": inputs["word"], "length": length, "pid": os.getpid(), **_WORKER}
        return Outcome(OK, measures=measures, files={"word.txt": inputs["word"].encode()})
