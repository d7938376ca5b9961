"""Run a batch's jobs on workers: `LocalRunner` (a process pool on this machine) and `RayRunner` (Ray actors,
local or on a cluster), one interface and one scheduler.

How a batch runs, and why:

- **Workers are warmed once.** Each worker process runs `JobKind.warm` before its first job (numba loads or
  compiles the wrap's kernels: ~3 s warm, ~20 s the first time after an install), then runs jobs until the end.
  A job's time limit starts when the job starts, never during the warm-up.
- **Each worker holds its next job** (`prefetch`, default 2: one running, one waiting) so that it never waits for
  the driver between jobs: the driver's round trip (receive the outputs, write the job folder, read the next
  pattern, send it) overlaps the next job. Measured overhead: benchmarks/bench_batch.py, BENCHMARKS.md.
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
import queue
import signal
import socket
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Hashable, Iterable, Sequence
from dataclasses import dataclass, field
from multiprocessing.connection import Connection
from multiprocessing.connection import wait as wait_connections
from typing import Any

from ..errors import ComputationError, InputError
from .outcome import FAILED, REFUSED, JobKind, Outcome

#: Warm-ups in a row that may fail (a worker that dies or raises before its first job) before the batch stops.
MAX_WARM_FAILURES = 3
#: Shared inputs a worker keeps (bodies, patterns, strokes; with a body, its collider).
WORKER_CACHE = 16
#: The longest the driver waits for news before it looks at the time limits again, seconds.
POLL_S = 0.5

OnOutcome = Callable[[Any, Outcome], None]


def ray_available() -> bool:
    """Whether Ray can be imported (the `batch` extra: pip install 'kitsuke[batch]')."""
    try:
        import ray  # noqa: F401
    except ImportError:
        return False
    return True


# -- worker side ------------------------------------------------------------------------------------------------
class InputCache:
    """The shared inputs a worker holds, least recently used dropped first. The local runner keeps a twin of each
    worker's cache (same operations in the same order) to know what it must send with a job."""

    def __init__(self, capacity: int = WORKER_CACHE):
        self.capacity = capacity
        self._items: collections.OrderedDict[Hashable, Any] = collections.OrderedDict()

    def __contains__(self, key: Hashable) -> bool:
        return key in self._items

    def admit(self, keys: Sequence[Hashable], fetch: Callable[[Hashable], Any]) -> tuple[list[Any], list[Hashable]]:
        """The values of `keys` (those missing fetched and added) and the keys evicted to make room. The keys held
        are touched first, so a job's own inputs are never evicted for each other (capacity >= keys of a job)."""
        for k in keys:
            if k in self._items:
                self._items.move_to_end(k)
        evicted = []
        for k in keys:
            if k not in self._items:
                self._items[k] = fetch(k)
                while len(self._items) > self.capacity:
                    evicted.append(self._items.popitem(last=False)[0])
        return [self._items[k] for k in keys], evicted


class WorkerCore:
    """What every worker does, whichever runner started it: warm once, then run jobs on cached inputs."""

    def __init__(self, kind: JobKind):
        self.kind = kind
        self.cache = InputCache()
        self._derived: dict[tuple[Hashable, str], Any] = {}
        self.name = f"{socket.gethostname()}:{os.getpid()}"

    def warm(self) -> str:
        _single_threaded()
        self.kind.warm()
        return self.name

    def run(self, job: Any, keys: dict[str, Hashable], fetch: Callable[[Hashable], Any]) -> Outcome:
        """Run `job` on its inputs (`keys`: name -> key; `fetch` gives a key's value when the cache lacks it).
        Never raises: an exception is the job's failure."""
        t0 = time.perf_counter()
        try:
            values, evicted = self.cache.admit(list(keys.values()), fetch)
            for gone in evicted:
                self._derived = {k: v for k, v in self._derived.items() if k[0] != gone}
            inputs = dict(zip(keys, values))

            def derived(name: str, factory: Callable[[Any], Any]) -> Any:
                k = (keys[name], getattr(factory, "__qualname__", repr(factory)))
                if k not in self._derived:
                    self._derived[k] = factory(inputs[name])
                return self._derived[k]

            outcome = self.kind.run(job, inputs, derived)
        except Exception as e:  # noqa: BLE001 - a job's bug or a library's internal error fails that job only
            outcome = Outcome(FAILED, f"internal error: {type(e).__name__}: {e}")
        outcome.seconds = time.perf_counter() - t0
        outcome.worker = self.name
        return outcome


def _single_threaded() -> None:
    """One numba thread per worker: workers are as many as cores, and threads beyond would only contend."""
    import numba

    numba.set_num_threads(1)


# -- driver side --------------------------------------------------------------------------------------------------
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
class _Task:
    index: int
    job: Any
    timeout_s: float | None
    keys: dict[str, Hashable] | None = None


@dataclass
class _Slot:
    """A worker as the driver sees it: the tasks sent to it in order (the first one runs once it is ready)."""

    id: int
    handle: Any = None
    ready: bool = False
    queue: collections.deque[_Task] = field(default_factory=collections.deque)
    started_at: float = 0.0
    worker: str = ""
    model: InputCache = field(default_factory=InputCache)


class Runner:
    """Runs a JobKind's jobs on workers; subclasses say how workers start, receive jobs and report.

    workers : how many (None: the cores of this machine, or of the cluster). timeout_s : a job's time limit
    (JobKind.timeout_s overrides it per job), or None. prefetch : jobs each worker holds (1 running + waiting).
    """

    name = "runner"

    def __init__(self, *, workers: int | None = None, timeout_s: float | None = None, prefetch: int = 2):
        if workers is not None and workers < 1:
            raise InputError(f"--workers must be at least 1, got {workers}")
        if timeout_s is not None and not timeout_s > 0:
            raise InputError(f"--timeout must be a positive number of seconds, got {timeout_s}")
        self.workers = workers
        self.timeout_s = timeout_s
        self.prefetch = max(1, prefetch)

    def use_log_dir(self, path: str | os.PathLike[str]) -> None:
        """Where workers may write their stdout and stderr (OUTDIR/.logs); runners whose workers keep their own
        logs (Ray's, in its session folder) ignore it."""

    # What a subclass provides.
    def _open(self, kind: JobKind) -> int:
        """Start what the workers need; return how many workers to run."""
        raise NotImplementedError

    def _start(self, slot: _Slot, kind: JobKind) -> None:
        """Start slot's worker (it warms up and reports ready)."""
        raise NotImplementedError

    def _send(self, slot: _Slot, task: _Task, inputs: SharedInputs) -> None:
        raise NotImplementedError

    def _poll(self, slots: list[_Slot], timeout: float) -> list[tuple[_Slot, str, Any]]:
        """Wait up to `timeout` s for news: (slot, "ready", worker name), (slot, "done", Outcome), (slot, "dead",
        reason). "done" is always about slot.queue[0]."""
        raise NotImplementedError

    def _stop(self, slot: _Slot) -> None:
        """Kill slot's worker now."""
        raise NotImplementedError

    def _forget(self, keys: list[Hashable]) -> None:
        """No job needs these shared inputs any more."""

    def _close(self, slots: list[_Slot]) -> None:
        """Stop every worker (`slots`: those still running) and what _open started."""

    # The scheduler.
    def run(self, kind: JobKind, jobs: Sequence[Any], on_outcome: OnOutcome) -> None:
        """Run every job, calling on_outcome(job, outcome) in the driver as each finishes (in any order)."""
        if not jobs:
            return
        inputs = SharedInputs(kind, jobs)
        pending = collections.deque(_Task(i, job, kind.timeout_s(job) or self.timeout_s) for i, job in enumerate(jobs))
        n = min(self._open(kind), len(jobs))
        slots: list[_Slot] = []
        next_id = 0
        warm_failures = 0

        def new_slot() -> _Slot:
            nonlocal next_id
            slot = _Slot(next_id)
            next_id += 1
            self._start(slot, kind)
            slots.append(slot)
            return slot

        def finish(slot: _Slot, outcome: Outcome) -> None:
            task = slot.queue.popleft()
            slot.started_at = time.monotonic()
            self._forget(inputs.close(task.keys or {}))
            on_outcome(task.job, outcome)

        def retire(slot: _Slot, reason: str) -> None:
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
        self, slots: list[_Slot], pending: collections.deque[_Task], inputs: SharedInputs, on_outcome: OnOutcome
    ) -> None:
        """Give each worker jobs until it holds `prefetch`; jobs whose inputs cannot be read end here."""
        for slot in slots:
            while pending and len(slot.queue) < self.prefetch:
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


# -- a process pool on this machine -------------------------------------------------------------------------------
class LocalRunner(Runner):
    """Workers are processes on this machine: fresh interpreters (`python -m kitsuke.batch._worker`, so nothing of
    the driver's state or its main script is inherited), each talking to the driver over a socket pair.
    log_dir: where each worker's stdout and stderr go (worker-N.log), or None to discard them."""

    name = "local"

    def __init__(self, *, log_dir: str | os.PathLike[str] | None = None, **kwargs: Any):
        super().__init__(**kwargs)
        self.log_dir = log_dir

    def use_log_dir(self, path: str | os.PathLike[str]) -> None:
        if self.log_dir is None:
            os.makedirs(path, exist_ok=True)
            self.log_dir = path

    def _open(self, kind: JobKind) -> int:
        return self.workers or os.cpu_count() or 1

    def _start(self, slot: _Slot, kind: JobKind) -> None:
        here, there = socket.socketpair()
        log = subprocess.DEVNULL
        if self.log_dir is not None:
            log = open(os.path.join(os.fspath(self.log_dir), f"worker-{slot.id}.log"), "ab")  # noqa: SIM115
        try:
            process = subprocess.Popen(
                [sys.executable, "-m", "kitsuke.batch._worker", str(there.fileno())],
                pass_fds=[there.fileno()],
                # The driver's import path, so that a JobKind defined beside the driver's script unpickles here.
                env={**os.environ, "PYTHONPATH": os.pathsep.join(p for p in sys.path if p)},
                stdin=subprocess.DEVNULL,
                stdout=log,
                stderr=log,
            )
        finally:
            there.close()
            if log is not subprocess.DEVNULL:
                log.close()
        conn = Connection(here.detach())
        conn.send(kind)
        slot.handle = (process, conn)

    def _send(self, slot: _Slot, task: _Task, inputs: SharedInputs) -> None:
        keys = list((task.keys or {}).values())
        missing: dict[Hashable, bytes] = {}
        slot.model.admit(keys, lambda k: missing.setdefault(k, inputs.pickled(k)))
        try:
            slot.handle[1].send((task.job, task.keys, missing))
        except OSError:
            pass  # the worker is dead: _poll reports it and the task goes back to the queue

    def _poll(self, slots: list[_Slot], timeout: float) -> list[tuple[_Slot, str, Any]]:
        by_conn = {s.handle[1]: s for s in slots}
        news = []
        for conn in wait_connections(list(by_conn), timeout):
            slot = by_conn[conn]
            try:
                while conn.poll():
                    news.append((slot, *conn.recv()))
            except (EOFError, OSError):  # the worker's end closed: it exited
                news.append((slot, "dead", _exit_reason(slot.handle[0])))
        return news

    def _stop(self, slot: _Slot) -> None:
        process, conn = slot.handle
        if process.poll() is None:
            process.kill()
        process.wait()
        conn.close()

    def _close(self, slots: list[_Slot]) -> None:
        for slot in slots:
            self._stop(slot)


def _exit_reason(process: subprocess.Popen) -> str:
    try:
        code = process.wait(5)
    except subprocess.TimeoutExpired:
        return "it closed its connection"
    if code < 0:
        return f"killed by {signal.Signals(-code).name}"
    return f"exit code {code}"


def local_worker(fd: int) -> None:
    """A local worker process (`kitsuke.batch._worker`): receive the job kind, warm, say ready, then run each job
    sent until the connection closes. A reader thread takes messages off the socket as they come, so the driver
    never blocks sending the next job, and the worker exits at once when the driver is gone (killed: nothing else
    would stop it)."""
    conn = Connection(fd)
    core = WorkerCore(conn.recv())
    try:
        conn.send(("ready", core.warm()))
    except Exception as e:  # noqa: BLE001 - reported to the driver, which counts failed warm-ups
        conn.send(("dead", f"its warm-up failed: {type(e).__name__}: {e}"))
        return
    inbox: queue.Queue = queue.Queue()

    def read() -> None:
        while True:
            try:
                inbox.put(conn.recv())
            except (EOFError, OSError):
                os._exit(0)

    threading.Thread(target=read, daemon=True).start()
    while True:
        job, keys, sent = inbox.get()
        outcome = core.run(job, keys, lambda k, sent=sent: pickle.loads(sent[k]))
        conn.send(("done", outcome))


# -- Ray --------------------------------------------------------------------------------------------------------
class RayRunner(Runner):
    """Workers are Ray actors (one CPU each). address: a running cluster to join (`ray start --head` prints it;
    "auto" finds the local one), or None to start a local Ray for this batch, stopped at its end. In a process
    where Ray is already initialised (a notebook, tests), that Ray is used and left running."""

    name = "ray"

    def __init__(self, *, address: str | None = None, **kwargs: Any):
        super().__init__(**kwargs)
        self.address = address
        self._started = False
        self._refs: dict[Any, tuple[_Slot, str, int]] = {}
        self._sent = 0
        self._stored: dict[Hashable, Any] = {}

    def _open(self, kind: JobKind) -> int:
        import logging

        import ray

        if not ray.is_initialized():
            local_cpus = None if self.address else (self.workers or os.cpu_count() or 1)
            ray.init(
                address=self.address or "local",  # "local": a new Ray for this batch, never a running one by chance
                num_cpus=local_cpus,
                include_dashboard=False,
                log_to_driver=False,
                logging_level=logging.WARNING,
            )
            self._started = True
        self._actor = ray.remote(num_cpus=1, max_restarts=0)(_RayWorker)
        return self.workers or max(1, int(ray.cluster_resources().get("CPU", 1)))

    def _start(self, slot: _Slot, kind: JobKind) -> None:
        slot.handle = self._actor.remote(kind)
        self._remember(slot.handle.warm.remote(), slot, "ready")

    def _send(self, slot: _Slot, task: _Task, inputs: SharedInputs) -> None:
        import ray

        refs = {}
        for key in (task.keys or {}).values():
            if key not in self._stored:
                self._stored[key] = ray.put(inputs.pickled(key))
            refs[key] = self._stored[key]
        # The refs travel inside a list, so Ray passes them as they are: a worker fetches only what it lacks.
        self._remember(slot.handle.run.remote(task.job, task.keys, [refs]), slot, "done")

    def _remember(self, ref: Any, slot: _Slot, what: str) -> None:
        self._sent += 1
        self._refs[ref] = (slot, what, self._sent)

    def _poll(self, slots: list[_Slot], timeout: float) -> list[tuple[_Slot, str, Any]]:
        import ray

        if not self._refs:
            time.sleep(timeout)
            return []
        ready, rest = ray.wait(list(self._refs), num_returns=1, timeout=timeout)
        if ready and rest:
            ready += ray.wait(rest, num_returns=len(rest), timeout=0)[0]
        news = []
        # In the order sent: a worker's results must come in the order of its queue.
        for ref in sorted(ready, key=lambda r: self._refs[r][2]):
            slot, what, _ = self._refs.pop(ref)
            try:
                news.append((slot, what, ray.get(ref)))
            except ray.exceptions.RayActorError as e:
                news.append((slot, "dead", _first_line(e)))
            except ray.exceptions.RayError as e:
                news.append((slot, "dead", f"{type(e).__name__}: {_first_line(e)}"))
        return news

    def _stop(self, slot: _Slot) -> None:
        import ray

        ray.kill(slot.handle, no_restart=True)
        self._refs = {r: v for r, v in self._refs.items() if v[0] is not slot}

    def _forget(self, keys: list[Hashable]) -> None:
        for key in keys:
            self._stored.pop(key, None)

    def _close(self, slots: list[_Slot]) -> None:
        import ray

        for slot in slots:
            ray.kill(slot.handle, no_restart=True)
        self._refs.clear()
        self._stored.clear()
        if self._started:
            ray.shutdown()
            self._started = False


def _first_line(e: BaseException) -> str:
    lines = [ln.strip() for ln in str(e).splitlines() if ln.strip()]
    return lines[0] if lines else type(e).__name__


class _RayWorker:
    """The Ray actor around a WorkerCore (made a Ray actor class by RayRunner: Ray is imported only there)."""

    def __init__(self, kind: JobKind):
        self.core = WorkerCore(kind)

    def warm(self) -> str:
        return self.core.warm()

    def run(self, job: Any, keys: dict[str, Hashable], refs: list[dict[Hashable, Any]]) -> Outcome:
        import ray

        return self.core.run(job, keys, lambda k: pickle.loads(ray.get(refs[0][k])))
