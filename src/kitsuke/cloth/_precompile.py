"""Compile the slowest numba kernels in another process while the first command after an install runs.

numba compiles each kernel on its first call and keeps it in its cache (`cache=True`), so only the first run after
an install (or a change of the code) pays. Of a cold `kitsuke dress` of GarmentCode's shirt (19.4 s on 2 cores,
2026-11-26), the polish's L-BFGS and energy take 6-8 s, and the polish comes last; of a cold `kitsuke demo`, the
kimono's layer order takes another 4 s. `precompile_in_background` starts a second process that compiles them into
the cache (`_collide.compile_layers` first when asked, as the wrap needs it early; then `_polish.compile_polish`)
while this one compiles and runs the wrap's earlier stages; when they are reached, they load from the cache. Last
come the length sweeps' and tethers' kernels (`_lengths.compile_lengths`, 2.3-2.8 s), which the wrap reaches after
its relaxation's: a cold `kitsuke demo` 29.7-32.8 -> 26.0-27.1 s and a cold `kitsuke dress` of the shirt
13.6-14.9 -> 12.2-12.6 s with them (2026-11-28, two runs each, alternated). With one core the two processes share
it and nothing is lost; a run whose cache is already warm starts nothing.
"""

from __future__ import annotations

import os
import subprocess
import sys


def _cached(kernel) -> bool:
    """Whether numba's cache holds `kernel` already (its index file exists); True when it cannot tell."""
    try:
        return os.path.exists(kernel._cache._cache_file._index_path)
    except AttributeError:  # another numba: its cache layout is not known here
        return True


def polish_cached() -> bool:
    """Whether numba's cache holds the polish's kernels already."""
    from ._lbfgs import minimise

    return _cached(minimise)


def lengths_cached() -> bool:
    """Whether numba's cache holds the length sweeps' and tethers' kernels already."""
    from ._kernels import project_tethers

    return _cached(project_tethers)


def layers_cached() -> bool:
    """Whether numba's cache holds the layer-order kernels already."""
    from ._collide_kernels import layer_moves

    return _cached(layer_moves)


def precompile_in_background(*, layers: bool = False) -> subprocess.Popen | None:
    """Start compiling the polish's kernels (first, with `layers`, the layer order's: a kimono; then the length
    sweeps' and tethers') in a background process when they are not cached yet; returns the process (it exits on
    its own, also after this one) or None."""
    steps = []
    if layers and not layers_cached():
        steps.append("from kitsuke.cloth._collide import compile_layers; compile_layers()")
    if not polish_cached():
        steps.append("from kitsuke.cloth._polish import compile_polish; compile_polish()")
    if not lengths_cached():  # after the polish: the wrap needs them sooner, but not before it compiled the rest
        steps.append("from kitsuke.cloth._lengths import compile_lengths; compile_lengths()")
    if not steps:
        return None
    try:
        return subprocess.Popen(
            [sys.executable, "-c", "; ".join(steps)],
            stdin=subprocess.DEVNULL,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            start_new_session=True,
        )
    except OSError:  # no process could be started: the kernels compile when they run, as they would anyway
        return None
