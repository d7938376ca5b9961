"""The worker side of every runner: warm once, then run jobs on the shared inputs it holds.

A worker keeps the inputs it was sent in a small LRU cache (`InputCache`), with what jobs derive from them (a
body's collider), so that a worker receives a body once and builds its collider once, however many jobs use it.
"""

from __future__ import annotations

import collections
import os
import socket
import time
from collections.abc import Callable, Hashable, Sequence
from typing import Any

from .outcome import FAILED, JobKind, Outcome

#: Shared inputs a worker keeps (bodies, patterns, strokes; with a body, its collider).
WORKER_CACHE = 16


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
