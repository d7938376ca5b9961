"""Physical facts of the relaxation: rest stays rest, stretch relaxes, folds open, pins hold, cloth drapes on a
sphere without entering it."""

from __future__ import annotations

import numpy as np
import pytest

from kitsuke.cloth import ClothModel, ClothParams, ClothState, grid_tube, relax, triangle_frames
from kitsuke.errors import InputError
from kitsuke.metrics import inverted_triangles, penetration, strain

from .conftest import flat_sheet

STILL = dict(gravity_step_m=0.0)


def rotation(rng) -> np.ndarray:
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    return q * np.sign(np.linalg.det(q))


def test_cloth_at_rest_stays_at_rest(rng):
    model, pos = flat_sheet(9, 7, **STILL)
    pos = pos @ rotation(rng).T + [0.3, 1.2, -0.1]  # any rigid placement is a rest state
    state = ClothState.new(model, pos)
    held = state.positions
    stats = relax(model, state, iterations=49)
    assert state.positions is held  # updated in place, whatever the number of iterations
    np.testing.assert_allclose(state.positions, pos, atol=1e-12)
    assert stats.iterations == 49 and stats.max_step_m < 1e-12 and stats.flipped == 0


def test_curved_rest_shape_stays_without_bending():
    faces, _, _ = grid_tube(12, 5, 0.02)
    i, j = np.arange(60) % 12, np.arange(60) // 12
    pos = np.c_[0.1 * np.sin(2 * np.pi * i / 12), 0.02 * j, 0.1 * np.cos(2 * np.pi * i / 12)]
    model = ClothModel.from_corners(faces, triangle_frames(pos, faces), params=ClothParams(bend_stiffness=0, **STILL))
    state = ClothState.new(model, pos)
    relax(model, state, iterations=30)
    np.testing.assert_allclose(state.positions, pos, atol=1e-12)


def test_stretched_sheet_relaxes_to_rest_lengths():
    model, pos = flat_sheet(12, 10, 0.02, **STILL)
    state = ClothState.new(model, pos * [1.25, 1.1, 1.0])
    before = strain(state.positions, model.edges, model.rest_lengths)
    assert before.max > 0.2
    relax(model, state, iterations=600)
    after = strain(state.positions, model.edges, model.rest_lengths)
    assert after.max < 0.01 and after.mean < 0.003
    # It shrank about its middle: no drift.
    np.testing.assert_allclose(state.positions.mean(axis=0), (pos * [1.25, 1.1, 1.0]).mean(axis=0), atol=1e-6)


def test_crumpled_sheet_flattens_back(rng):
    model, pos = flat_sheet(10, 10, 0.02, bend_stiffness=0.3, **STILL)
    state = ClothState.new(model, pos + rng.normal(0, 0.004, pos.shape))
    relax(model, state, iterations=800)
    s = strain(state.positions, model.edges, model.rest_lengths)
    assert s.max < 0.01
    # Flat again: the vertices lie in a plane (smallest principal extent tiny).
    x = state.positions - state.positions.mean(axis=0)
    assert np.linalg.svd(x, compute_uv=False)[-1] / np.sqrt(len(x)) < 1e-3  # from 4 mm RMS


def fold_corner(model, pos):
    """Reflect a corner vertex that belongs to one triangle only through the line of that triangle's opposite
    edge: the triangle lies folded back over its neighbour."""
    counts = np.bincount(model.faces.reshape(-1))
    v = int(np.flatnonzero(counts == 1)[0])
    t = int(np.flatnonzero((model.faces == v).any(axis=1))[0])
    a, b = [k for k in model.faces[t] if k != v]
    p = pos.copy()
    e = (p[b] - p[a]) / np.linalg.norm(p[b] - p[a])
    foot = p[a] + ((p[v] - p[a]) @ e) * e
    p[v] = foot + 0.98 * (foot - p[v]) + [0, 0, 0.002]
    return p


def test_folded_triangle_is_unflipped():
    model, pos = flat_sheet(8, 8, **STILL)
    folded = fold_corner(model, pos)
    assert inverted_triangles(folded, model.faces).sum() >= 1
    state = ClothState.new(model, folded)
    stats = relax(model, state, iterations=1)
    assert stats.flipped >= 1
    relax(model, state, iterations=200)
    assert not inverted_triangles(state.positions, model.faces, rest_areas=model.rest_areas).any()
    assert strain(state.positions, model.edges, model.rest_lengths).max < 0.01


def test_folded_triangle_stays_folded_without_unflip():
    model, pos = flat_sheet(8, 8, unflip=False, bend_stiffness=0.0, **STILL)
    state = ClothState.new(model, fold_corner(model, pos))
    relax(model, state, iterations=200)
    assert inverted_triangles(state.positions, model.faces).any()  # the un-flipping above is what fixes it


def test_pins_hold_and_hanging_sheet_barely_stretches():
    model, pos = flat_sheet(10, 25, 0.02)
    pos = pos[:, [0, 1, 2]]
    top = pos[:, 1] == pos[:, 1].max()
    state = ClothState.new(model, pos, pinned=top)
    relax(model, state, iterations=400)
    np.testing.assert_array_equal(state.positions[top], pos[top])
    s = strain(state.positions, model.edges, model.rest_lengths)
    # Hanging 50 cm from its pins, the strain limit keeps every edge near its rest length.
    assert s.stretched <= model.params.max_stretch + 1e-9
    assert s.mean < 0.005 and s.max < 0.02
    # Without the limit, the gravity moves accumulate down the chain and stretch the top.
    free = ClothModel.from_corners(model.faces, model.rest_corners, params=ClothParams(max_stretch=None))
    loose = ClothState.new(free, pos, pinned=top)
    relax(free, loose, iterations=400)
    assert strain(loose.positions, free.edges, free.rest_lengths).max > 0.1


def test_inactive_triangles_do_not_move(rng):
    model, pos = flat_sheet(8, 6)
    active = np.ones(model.n_faces, dtype=bool)
    active[model.faces.max(axis=1) >= 24] = False  # only the bottom three rows of vertices take part
    state = ClothState.new(model, pos, face_active=active)
    relax(model, state, iterations=20)
    untouched = np.setdiff1d(np.arange(model.n_vertices), model.faces[active].reshape(-1))
    np.testing.assert_array_equal(state.positions[untouched], pos[untouched])
    assert (state.positions[:24, 1] < pos[:24, 1]).any()


def test_sheet_dropped_on_sphere_drapes_outside(sphere, sphere_collider):
    model, pos = flat_sheet(21, 21, 0.015, gravity_step_m=0.001)
    pos = pos - pos.mean(axis=0)
    pos = pos[:, [0, 2, 1]] + [0.0, 0.13, 0.0]  # horizontal, 3 cm above the sphere's top
    state = ClothState.new(model, pos)
    relax(model, state, sphere_collider, iterations=300)
    p = state.positions
    pen = penetration(p, sphere, threshold_m=0.0)
    assert pen.count == 0
    r = np.linalg.norm(p, axis=1)
    assert r.min() >= 0.1 - 1e-3  # nothing inside (the icosphere's faces lie up to 1 mm inside its radius)
    # It draped: the middle rests on the top, the corners hang well below it.
    centre = np.argmin(np.linalg.norm(pos[:, [0, 2]], axis=1))
    assert p[centre, 1] == pytest.approx(0.1 + model.params.contact_offset_m, abs=0.003)
    assert p[:, 1].min() < 0.03
    # A flat sheet cannot cover a sphere without compression; it must not stretch, though.
    assert strain(p, model.edges, model.rest_lengths).stretched < 0.02


def test_relaxing_around_the_free_vertices_alone_changes_nothing(sphere, sphere_collider, rng):
    """`around_free` (a small free region of a large cloth: untangling) works on the triangles near the free
    vertices only and collides only what moved: bit for bit the full relaxation's result."""
    model, pos = flat_sheet(21, 21, 0.015, bend_stiffness=0.3, gravity_step_m=0.0, unflip=True)
    pos = pos - pos.mean(axis=0)
    pos = pos[:, [0, 2, 1]] + [0.0, 0.105, 0.0] + rng.normal(scale=0.004, size=pos.shape)  # crumpled, on the top
    free = np.linalg.norm(pos[:, [0, 2]], axis=1) < 0.05
    runs = []
    for around_free in (False, True):
        state = ClothState.new(model, pos.copy()).holding(~free)
        relax(model, state, sphere_collider, iterations=40, around_free=around_free)
        runs.append(state.positions.copy())
    np.testing.assert_array_equal(runs[0], runs[1])
    assert np.abs(runs[0][free] - pos[free]).max() > 1e-3 and (runs[0][~free] == pos[~free]).all()


def test_relax_rejects_bad_input():
    model, pos = flat_sheet(4, 4)
    other, _ = flat_sheet(5, 4)
    state = ClothState.new(model, pos)
    with pytest.raises(InputError, match="state does not fit"):
        relax(other, state)
    with pytest.raises(InputError, match="iterations"):
        relax(model, state, iterations=-1)
    with pytest.raises(InputError, match="collider"):
        relax(model, state, "body")  # type: ignore[arg-type]
