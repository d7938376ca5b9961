"""Edge-length restoration: stretched cloth goes back to its rest lengths, pins and inactive cloth stay exactly
still, and collision keeps it out of the body while it does."""

from __future__ import annotations

import numpy as np
import pytest

from kitsuke.cloth import ClothState, restore_lengths
from kitsuke.errors import InputError
from kitsuke.metrics import penetration, strain

from .conftest import flat_sheet


def test_a_stretched_sheet_goes_back_to_its_rest_lengths_and_pins_hold():
    model, rest = flat_sheet(12, 10, 0.02, gravity_step_m=0.0)
    stretched = rest * [1.15, 1.0, 1.0]  # 15 % along x
    pins = rest[:, 0] == 0.0  # the left column
    state = ClothState.new(model, stretched, pinned=pins)
    assert strain(stretched, model.edges, model.rest_lengths).max > 0.14
    stats = restore_lengths(model, state, sweeps=400)
    s = strain(state.positions, model.edges, model.rest_lengths)
    assert s.max < 0.005 and s.mean < 0.001
    assert stats.sweeps == 400 and stats.worst_error_m < 1e-4
    np.testing.assert_array_equal(state.positions[pins], stretched[pins])
    # It shrank towards the pins: the right column came back by about the stretch.
    right = rest[:, 0] == rest[:, 0].max()
    assert np.median(stretched[right, 0] - state.positions[right, 0]) > 0.8 * 0.15 * rest[:, 0].max()


def test_tolerance_stops_early_and_inactive_cloth_does_not_move():
    model, rest = flat_sheet(8, 6, 0.02, gravity_step_m=0.0)
    stretched = rest * [1.0, 1.1, 1.0]
    active = np.ones(model.n_faces, dtype=bool)
    active[: model.n_faces // 2] = False
    state = ClothState.new(model, stretched, face_active=active)
    stats = restore_lengths(model, state, sweeps=1000, tolerance_m=1e-6)
    assert stats.sweeps < 1000 and stats.worst_error_m <= 1e-6
    still = np.ones(model.n_vertices, dtype=bool)
    still[model.faces[active].reshape(-1)] = False
    assert still.any()
    np.testing.assert_array_equal(state.positions[still], stretched[still])


def test_a_sheet_stretched_over_a_sphere_shrinks_and_keeps_out_of_it(sphere, sphere_collider):
    """A sheet laid over the top of the 10 cm sphere, 15 % too large (each point put on the sphere straight below
    where it would be), its centre pinned: restoring its lengths takes out most of the strain (all of it cannot
    go: a sphere is not developable), and the collision updates keep every vertex outside."""
    model, rest = flat_sheet(11, 11, 0.015, gravity_step_m=0.0)
    xz = (rest[:, :2] - rest[:, :2].mean(axis=0)) * 1.15
    up = np.sqrt(np.maximum(0.103**2 - (xz**2).sum(axis=1), 0.0))
    pos = np.c_[xz[:, 0], up, xz[:, 1]]
    centre = np.zeros(model.n_vertices, dtype=bool)
    centre[np.argmin((xz**2).sum(axis=1))] = True
    state = ClothState.new(model, pos, pinned=centre)
    before = strain(pos, model.edges, model.rest_lengths).mean
    restore_lengths(model, state, sphere_collider, sweeps=300)
    assert strain(state.positions, model.edges, model.rest_lengths).mean < 0.25 * before
    assert penetration(state.positions, sphere, threshold_m=0.0005).count == 0
    np.testing.assert_array_equal(state.positions[centre], pos[centre])


def test_bad_arguments_are_rejected():
    model, rest = flat_sheet(4, 4, 0.02)
    state = ClothState.new(model, rest)
    for kw in (dict(sweeps=-1), dict(collide_every=0), dict(tolerance_m=float("nan"))):
        with pytest.raises(InputError):
            restore_lengths(model, state, **kw)
    with pytest.raises(InputError):
        restore_lengths(model, rest)
