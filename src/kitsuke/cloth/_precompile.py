"""Compile the slowest numba kernel in another process while the first command after an install runs.

numba compiles each kernel on its first call and keeps it in its cache (`cache=True`), so only the first run after
an install (or a change of the code) pays. Of a cold `kitsuke dress` (24 s on 2 cores, 2026-11-26), the polish's
L-BFGS and energy take 7-8 s, and the polish comes last. `precompile_in_background` starts a second process that
compiles them (`_polish.compile_polish`) into the cache while this one compiles and runs the wrap's earlier
stages; when the polish is reached, its kernels load from the cache. With one core the two share it and nothing
is lost; a run whose cache is already warm starts nothing.
"""

from __future__ import annotations

import os
import subprocess
import sys


def polish_cached() -> bool:
    """Whether numba's cache holds the polish's kernels already (their index file exists); True when it cannot
    tell (so nothing is started)."""
    from ._lbfgs import minimise

    try:
        return os.path.exists(minimise._cache._cache_file._index_path)
    except AttributeError:  # another numba: its cache layout is not known here
        return True


def precompile_in_background() -> subprocess.Popen | None:
    """Start compiling the polish's kernels in a background process when they are not cached yet; returns the
    process (it exits on its own, also after this one) or None."""
    if polish_cached():
        return None
    code = "from kitsuke.cloth._polish import compile_polish; compile_polish()"
    try:
        return subprocess.Popen(
            [sys.executable, "-c", code],
            stdin=subprocess.DEVNULL,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            start_new_session=True,
        )
    except OSError:  # no process could be started: the polish compiles when it runs, as it would anyway
        return None
