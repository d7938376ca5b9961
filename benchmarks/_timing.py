"""Shared timing helper for the benchmark scripts (run them from the repository root: python benchmarks/NAME.py)."""

from __future__ import annotations

import statistics
import time
from collections.abc import Callable
from typing import Literal


def timeit(
    fn: Callable[[], object], repeat: int = 7, *, stat: Literal["median", "min"] = "median", warmup: bool = True
) -> float:
    """Wall time of one call to `fn`, seconds: the median (default) or the best of `repeat` calls.

    A warm-up call first (imports, numba compilation, caches) unless `warmup` is False. Use "min" on a shared,
    noisy machine, where the best run is the one least disturbed by other work.
    """
    if warmup:
        fn()
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return statistics.median(times) if stat == "median" else min(times)
