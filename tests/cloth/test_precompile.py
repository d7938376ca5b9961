"""The kernels compiled ahead (in a background process on a cold start) are the very ones the wrap calls: the
same argument types, so the wrap loads them from numba's cache instead of compiling them again."""

from __future__ import annotations

import numpy as np

from kitsuke.cloth import ClothState, Tethers, compile_polish, keep_layers, polish
from kitsuke.cloth import _collide_kernels as K
from kitsuke.cloth import _kernels as CK
from kitsuke.cloth._collide import compile_layers
from kitsuke.cloth._lbfgs import minimise
from kitsuke.cloth._lengths import compile_lengths, restore_lengths
from kitsuke.cloth._precompile import (
    layers_cached,
    lengths_cached,
    polish_cached,
    precompile_in_background,
)

from .conftest import flat_sheet
from .test_layers import two_sheets


def test_compile_polish_gives_the_signature_polish_calls(sphere_collider):
    compile_polish()
    assert len(minimise.signatures) == 1
    model, pos = flat_sheet(6, 5, 0.02)
    pos = pos + [0.0, 0.0, 0.101]  # over the sphere's top
    state = ClothState.new(model, pos)
    tethers = Tethers.from_polylines([(np.array([0]), np.full((1, 3), 1 / 3), pos[:2])], model.faces, 0.005)
    polish(model, state, sphere_collider, rounds=1, iterations=2, tethers=tethers)
    polish(model, state, sphere_collider, rounds=1, iterations=2)
    assert len(minimise.signatures) == 1  # the same overload: nothing compiled for the real call


def test_compile_layers_gives_the_signatures_keep_layers_calls():
    compile_layers()
    assert len(K.layer_moves.signatures) == 1 and len(K.point_grid.signatures) == 1
    model, pos = two_sheets(np.random.default_rng(0))
    keep_layers(model, ClothState.new(model, pos))
    assert len(K.layer_moves.signatures) == 1 and len(K.point_grid.signatures) == 1


def test_compile_lengths_gives_the_signatures_the_wrap_calls(sphere_collider):
    compile_lengths()
    kernels = (CK.project_lengths, CK.project_band, CK.project_tethers)
    compiled = [len(k.signatures) for k in kernels]
    assert compiled[2] >= 2  # the tethers' kernel with and without its stamps
    model, pos = flat_sheet(6, 5, 0.02)
    pos = 1.05 * pos + [0.0, 0.0, 0.101]  # stretched, over the sphere's top
    tethers = Tethers.from_polylines([(np.array([0]), np.full((1, 3), 1 / 3), pos[:2])], model.faces, 0.005)
    for kw in ({"chebyshev_rho": 0.99, "sweeps": 40}, {"over_relaxation": 1.5}, {"band": 0.045}):  # as the wrap
        restore_lengths(model, ClothState.new(model, pos.copy()), sphere_collider, tethers=tethers, **kw)
    assert [len(k.signatures) for k in kernels] == compiled  # nothing compiled for the real calls


def test_nothing_is_started_when_the_cache_is_warm():
    compile_polish()
    compile_layers()
    compile_lengths()
    assert polish_cached() and layers_cached() and lengths_cached()  # this process's calls wrote (or found) them
    assert precompile_in_background(layers=True) is None
