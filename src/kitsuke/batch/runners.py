"""Run a batch's jobs on workers: one scheduler, whatever the workers are: `LocalRunner` (`local`, a process
pool on this machine) and `RayRunner` (`on_ray`, Ray actors, local or on a cluster) say only how workers start,
receive jobs and report.

How a batch runs, and why:

- **Workers are warmed once.** Each worker process runs `JobKind.warm` before its first job (numba loads or
  compiles the wrap's kernels: 1-2 s, ~20 s the first time after an install), then runs jobs until the end.
  A job's time limit starts when the job starts, never during the warm-up.
- **A local worker holds its next job** (`prefetch` 2: one running, one waiting), so that it never waits for the
  driver between jobs: the driver's round trip (receive the outputs, write the job folder, read the next pattern,
  send it) overlaps the next job. A Ray worker holds one (`prefetch` 1): Ray sends a result back after its task
  returns, so a worker killed by the job after it (out of memory, a crash) could take that result with it and
  the wrong job would be blamed; the round trip costs a few milliseconds per job instead. Measured overhead:
  benchmarks/bench_batch.py, BENCHMARKS.md.
- **Shared inputs are read once.** The driver reads each body and pattern the first time a job needs it and
  frees it after the last; each worker keeps the inputs it was sent in a small LRU cache, with what it derived
  from them (a body's collider), so a worker receives a body once and builds its collider once. Ray sends them
  through its object store; the local pool through the worker's pipe, only when the worker does not hold them.
- **Failures stay with their job.** A job that raises is recorded as failed with the exception's line; one that
  runs past its time limit has its worker killed (a hung numba kernel cannot be interrupted any other way) and is
  recorded as failed; one whose worker dies (killed, out of memory, a crash in native code) too. The jobs that
  worker held but had not started go back to the queue, a fresh worker is started and warmed, and the batch goes
  on. A worker that cannot even warm up three times running stops the batch (ComputationError): then no job could
  run.
- Workers run numba on one thread each: the batch's parallelism is across jobs (workers = cores).
"""

from __future__ import annotations

import collections
import os
import pickle
import time
from collections.abc import Callable, Hashable, Iterable, Sequence
from dataclasses import dataclass, field
from typing import Any

from ..errors import ComputationError, InputError
from .outcome import FAILED, REFUSED, JobKind, Outcome
from .workers import InputCache

#: Warm-ups in a row that may fail (a worker that dies or raises before its first job) before the batch stops.
MAX_WARM_FAILURES = 3
#: The longest the driver waits for news before it looks at the time limits again, seconds.
POLL_S = 0.5

OnOutcome = Callable[[Any, Outcome], None]


class SharedInputs:
    """The driver's shared inputs: each read on first use, kept until the last job needing it is finished.

    A read that fails is kept as the outcome of every job needing that input (a broken pattern file refuses every
    job on it, read once)."""

    def __init__(self, kind: JobKind, jobs: Iterable[Any]):
        self.kind = kind
        self._uses: collections.Counter[Hashable] = collections.Counter()
        for job in jobs:
            self._uses.update(kind.inputs(job).values())
        self._values: dict[Hashable, Any] = {}
        self._pickled: dict[Hashable, bytes] = {}
        self._failed: dict[Hashable, Outcome] = {}

    def open(self, job: Any) -> dict[str, Hashable] | Outcome:
        """The keys of `job`'s inputs, each read now if not yet; or the Outcome refusing the job."""
        keys = self.kind.inputs(job)
        for key in keys.values():
            if key not in self._values and key not in self._failed:
                t0 = time.perf_counter()
                try:
                    self._values[key] = self.kind.load(key)
                except InputError as e:
                    self._failed[key] = Outcome(REFUSED, str(e), seconds=time.perf_counter() - t0)
                except Exception as e:  # noqa: BLE001 - an internal error reading one input fails its jobs only
                    self._failed[key] = Outcome(FAILED, f"internal error reading an input: {type(e).__name__}: {e}")
            if key in self._failed:
                self.close(keys)
                f = self._failed[key]
                return Outcome(f.status, f.reason, seconds=f.seconds)
        return keys

    def pickled(self, key: Hashable) -> bytes:
        """`key`'s value pickled, once (every worker gets the same bytes)."""
        if key not in self._pickled:
            self._pickled[key] = pickle.dumps(self._values[key], protocol=pickle.HIGHEST_PROTOCOL)
        return self._pickled[key]

    def close(self, keys: dict[str, Hashable]) -> list[Hashable]:
        """A job that needed `keys` is finished; returns the keys no job needs any more (freed here)."""
        freed = []
        for key in keys.values():
            self._uses[key] -= 1
            if self._uses[key] <= 0:
                self._values.pop(key, None)
                self._pickled.pop(key, None)
                freed.append(key)
        return freed


@dataclass
class Task:
    """A job on its way: its time limit, and its shared inputs' keys once read."""

    job: Any
    timeout_s: float | None
    keys: dict[str, Hashable] | None = None


@dataclass
class WorkerSlot:
    """A worker as the driver sees it: the tasks sent to it in order (the first one runs once it is ready)."""

    id: int
    handle: Any = None
    ready: bool = False
    queue: collections.deque[Task] = field(default_factory=collections.deque)
    started_at: float = 0.0
    worker: str = ""
    model: InputCache = field(default_factory=InputCache)


class Runner:
    """Runs a JobKind's jobs on workers; subclasses say how workers start, receive jobs and report.

    workers : how many (None: the cores of this machine, or of the cluster). timeout_s : a job's time limit
    (JobKind.timeout_s overrides it per job), or None. prefetch : jobs each worker holds (1 running + waiting),
    or None for the runner's default.
    """

    name = "a runner"

    #: Jobs a worker holds unless told otherwise.
    prefetch_default = 2

    def __init__(self, *, workers: int | None = None, timeout_s: float | None = None, prefetch: int | None = None):
        if workers is not None and workers < 1:
            raise InputError(f"--workers must be at least 1, got {workers}")
        if timeout_s is not None and not timeout_s > 0:
            raise InputError(f"--timeout must be a positive number of seconds, got {timeout_s}")
        self.workers = workers
        self.timeout_s = timeout_s
        self.prefetch = max(1, prefetch or self.prefetch_default)

    def describe(self) -> str:
        """What the runner runs on, for a progress line."""
        workers = "a worker per core" if self.workers is None else f"{self.workers} worker(s)"
        return f"{self.name} ({workers})"

    def use_log_dir(self, path: str | os.PathLike[str]) -> None:
        """Where workers may write their stdout and stderr (OUTDIR/.logs); runners whose workers keep their own
        logs (Ray's, in its session folder) ignore it."""

    # What a subclass provides.
    def _open(self, kind: JobKind) -> int:
        """Start what the workers need; return how many workers to run."""
        raise NotImplementedError

    def _start(self, slot: WorkerSlot, kind: JobKind) -> None:
        """Start slot's worker (it warms up and reports ready)."""
        raise NotImplementedError

    def _send(self, slot: WorkerSlot, task: Task, inputs: SharedInputs) -> None:
        raise NotImplementedError

    def _poll(self, slots: list[WorkerSlot], timeout: float) -> list[tuple[WorkerSlot, str, Any]]:
        """Wait up to `timeout` s for news: (slot, "ready", worker name), (slot, "done", Outcome), (slot, "dead",
        reason). "done" is always about slot.queue[0]."""
        raise NotImplementedError

    def _stop(self, slot: WorkerSlot) -> None:
        """Kill slot's worker now."""
        raise NotImplementedError

    def _forget(self, keys: list[Hashable]) -> None:
        """No job needs these shared inputs any more."""

    def _close(self, slots: list[WorkerSlot]) -> None:
        """Stop every worker (`slots`: those still running) and what _open started."""

    # The scheduler.
    def run(self, kind: JobKind, jobs: Sequence[Any], on_outcome: OnOutcome) -> None:
        """Run every job, calling on_outcome(job, outcome) in the driver as each finishes (in any order)."""
        if not jobs:
            return
        inputs = SharedInputs(kind, jobs)
        pending = collections.deque(Task(job, kind.timeout_s(job) or self.timeout_s) for job in jobs)
        n = min(self._open(kind), len(jobs))
        slots: list[WorkerSlot] = []
        next_id = 0
        warm_failures = 0

        def new_slot() -> WorkerSlot:
            nonlocal next_id
            slot = WorkerSlot(next_id)
            next_id += 1
            self._start(slot, kind)
            slots.append(slot)
            return slot

        def finish(slot: WorkerSlot, outcome: Outcome) -> None:
            task = slot.queue.popleft()
            slot.started_at = time.monotonic()
            self._forget(inputs.close(task.keys or {}))
            on_outcome(task.job, outcome)

        def retire(slot: WorkerSlot, reason: str) -> None:
            """The slot's worker is gone: its running job failed with `reason`, the rest go back to the queue."""
            slots.remove(slot)
            if slot.ready and slot.queue:
                finish(slot, Outcome(FAILED, reason, seconds=time.monotonic() - slot.started_at, worker=slot.worker))
            pending.extendleft(reversed(slot.queue))
            if pending or any(s.queue for s in slots):
                new_slot()

        try:
            for _ in range(n):
                new_slot()
            while pending or any(s.queue for s in slots):
                self._dispatch(slots, pending, inputs, on_outcome)
                now = time.monotonic()
                deadlines = [
                    s.started_at + s.queue[0].timeout_s for s in slots if s.ready and s.queue and s.queue[0].timeout_s
                ]
                wait = min([POLL_S, *(d - now for d in deadlines)])
                for slot, what, data in self._poll(list(slots), max(wait, 0.0)):
                    if slot not in slots:
                        continue  # news from a worker already retired
                    if what == "ready":
                        slot.ready, slot.worker, slot.started_at = True, data, time.monotonic()
                        warm_failures = 0
                    elif what == "done":
                        finish(slot, data)
                    else:
                        if not slot.ready:
                            warm_failures += 1
                            if warm_failures >= MAX_WARM_FAILURES:
                                raise ComputationError("batch", f"no worker could start: {data}")
                        self._stop(slot)
                        retire(slot, f"its worker died: {data}")
                now = time.monotonic()
                for slot in list(slots):
                    task = slot.queue[0] if slot.ready and slot.queue else None
                    if task is not None and task.timeout_s and now - slot.started_at > task.timeout_s:
                        self._stop(slot)
                        retire(slot, f"timed out after {task.timeout_s:g} s (its worker was stopped)")
        finally:
            self._close(slots)

    def _dispatch(
        self, slots: list[WorkerSlot], pending: collections.deque[Task], inputs: SharedInputs, on_outcome: OnOutcome
    ) -> None:
        """Give each warm worker jobs until it holds `prefetch` (a worker still starting holds none: on a cluster
        short of CPUs it may never start); jobs whose inputs cannot be read end here."""
        for slot in slots:
            while slot.ready and pending and len(slot.queue) < self.prefetch:
                task = pending.popleft()
                if task.keys is None:
                    opened = inputs.open(task.job)
                    if isinstance(opened, Outcome):
                        on_outcome(task.job, opened)
                        continue
                    task.keys = opened
                self._send(slot, task, inputs)
                if not slot.queue:
                    slot.started_at = time.monotonic()
                slot.queue.append(task)
