"""`RayRunner`: the batch's workers as Ray actors, on a local Ray started for the batch or a cluster's.

Ray is imported only when a RayRunner runs (it is the optional `batch` extra).
"""

from __future__ import annotations

import os
import pickle
import time
from collections.abc import Hashable
from typing import Any

from .outcome import JobKind, Outcome
from .runners import Runner, SharedInputs, Task, WorkerSlot
from .workers import WorkerCore


def ray_available() -> bool:
    """Whether Ray can be imported (the `batch` extra: pip install 'kitsuke[batch]')."""
    try:
        import ray  # noqa: F401
    except ImportError:
        return False
    return True


class RayRunner(Runner):
    """Workers are Ray actors (one CPU each). address: a running cluster to join (`ray start --head` prints it;
    "auto" finds the local one), or None to start a local Ray for this batch, stopped at its end. In a process
    where Ray is already initialised (a notebook, tests), that Ray is used and left running."""

    name = "Ray"
    #: One job at a time: see kitsuke.batch.runners (a result still on its way dies with its worker).
    prefetch_default = 1

    def __init__(self, *, address: str | None = None, **kwargs: Any):
        super().__init__(**kwargs)
        self.address = address
        self._started = False
        self._refs: dict[Any, tuple[WorkerSlot, str, int]] = {}
        self._sent = 0
        self._stored: dict[Hashable, Any] = {}

    def describe(self) -> str:
        where = f"the cluster at {self.address}" if self.address else "a local Ray"
        workers = "a worker per CPU" if self.workers is None else f"{self.workers} worker(s)"
        return f"{where} ({workers})"

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

    def _start(self, slot: WorkerSlot, kind: JobKind) -> None:
        slot.handle = self._actor.remote(kind)
        self._remember(slot.handle.warm.remote(), slot, "ready")

    def _send(self, slot: WorkerSlot, task: Task, inputs: SharedInputs) -> None:
        import ray

        refs = {}
        for key in (task.keys or {}).values():
            if key not in self._stored:
                self._stored[key] = ray.put(inputs.pickled(key))
            refs[key] = self._stored[key]
        # The refs travel inside a list, so Ray passes them as they are: a worker fetches only what it lacks.
        self._remember(slot.handle.run.remote(task.job, task.keys, [refs]), slot, "done")

    def _remember(self, ref: Any, slot: WorkerSlot, what: str) -> None:
        self._sent += 1
        self._refs[ref] = (slot, what, self._sent)

    def _poll(self, slots: list[WorkerSlot], timeout: float) -> list[tuple[WorkerSlot, str, Any]]:
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
                cause = getattr(e, "cause", None) or e  # a RayTaskError carries the worker's own exception
                news.append((slot, "dead", f"{type(cause).__name__}: {_first_line(cause)}"))
        return news

    def _stop(self, slot: WorkerSlot) -> None:
        import ray

        ray.kill(slot.handle, no_restart=True)
        self._refs = {r: v for r, v in self._refs.items() if v[0] is not slot}

    def _forget(self, keys: list[Hashable]) -> None:
        for key in keys:
            self._stored.pop(key, None)

    def _close(self, slots: list[WorkerSlot]) -> None:
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
