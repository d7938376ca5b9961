"""Untangling opens folded triangles by relaxing only the cloth around them: the fold opens, the rest of the
cloth does not move at all, pins hold."""

from __future__ import annotations

import numpy as np
import pytest

from kitsuke.cloth import ClothState, Tethers, folded_faces, untangle
from kitsuke.errors import InputError
from kitsuke.metrics import inverted_triangles, strain

from .conftest import flat_sheet
from .test_relax import fold_corner

STILL = dict(gravity_step_m=0.0)


def folded_sheet():
    model, pos = flat_sheet(12, 12, 0.02, **STILL)
    return model, fold_corner(model, pos), pos


def test_a_folded_corner_opens_and_far_cloth_stays_exactly_still():
    model, folded, rest = folded_sheet()
    assert inverted_triangles(folded, model.faces).sum() >= 1
    state = ClothState.new(model, folded)
    assert folded_faces(model, state).sum() >= 1
    stats = untangle(model, state, rings=3)
    assert stats.before >= 1 and stats.after == 0 and stats.rounds >= 1
    assert not inverted_triangles(state.positions, model.faces, rest_areas=model.rest_areas).any()
    moved = np.linalg.norm(state.positions - folded, axis=1) > 0
    # Only the few rings around the fold were free: most of the 144-vertex sheet is bit-identical.
    assert 0 < moved.sum() <= stats.moved
    assert (~moved).sum() > 100
    np.testing.assert_array_equal(state.positions[~moved], folded[~moved])
    # The opened corner is back near its rest shape.
    assert strain(state.positions, model.edges, model.rest_lengths).max < 0.05


def test_pinned_vertices_never_move_and_nothing_happens_without_folds():
    model, folded, rest = folded_sheet()
    v = int(np.flatnonzero(np.linalg.norm(folded - rest, axis=1) > 0)[0])  # the folded corner vertex
    pins = np.zeros(model.n_vertices, dtype=bool)
    pins[v] = True
    state = ClothState.new(model, folded, pinned=pins)
    untangle(model, state)
    assert (state.positions[v] == folded[v]).all()
    assert (state.pinned == pins).all()  # the caller's pins are given back

    flat = ClothState.new(model, rest)
    stats = untangle(model, flat)
    assert stats.rounds == 0 and stats.before == 0 and (flat.positions == rest).all()


def test_tethers_hold_inside_the_untangled_region():
    """A point on the cloth next to the fold, tethered (2 mm reach) to a line 1 cm above where it lies: the fold
    opens, the point ends within reach of its line, and the cloth outside the region still does not move."""
    model, folded, rest = folded_sheet()
    state = ClothState.new(model, folded)
    fold = np.flatnonzero(folded_faces(model, state))
    ring = np.flatnonzero(np.isin(model.faces, model.faces[fold]).any(axis=1))
    face = int(np.setdiff1d(ring, fold)[0])
    p0 = folded[model.faces[face]].mean(axis=0)
    line = np.array([p0 + [-0.02, 0, 0.01], p0 + [0.02, 0, 0.01]])
    tethers = Tethers.from_polylines([([face], [[1 / 3, 1 / 3, 1 / 3]], line)], model.faces, 0.002)
    stats = untangle(model, state, rings=3, tethers=tethers)
    assert stats.after == 0
    p = state.positions[model.faces[face]].mean(axis=0)
    assert abs(p[0] - p0[0]) < 0.02  # within the line's ends, which run along x: its distance is in y and z
    assert np.linalg.norm(p[1:] - line[0, 1:]) <= 0.002 + 1e-9
    moved = np.linalg.norm(state.positions - folded, axis=1) > 0
    assert moved.sum() <= stats.moved and (~moved).sum() > 100


def test_untangle_rejects_bad_arguments():
    model, folded, _ = folded_sheet()
    state = ClothState.new(model, folded)
    with pytest.raises(InputError):
        untangle(model, state, rings=0)
    with pytest.raises(InputError):
        untangle(model, state, iterations=0)
