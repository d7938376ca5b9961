"""Sewing (`kitsuke.cloth.sew`): open seams closed by the dynamic solver a little at a time, round the body."""

from __future__ import annotations

import numpy as np

from kitsuke.cloth import BodyCollider, ClothModel, ClothState, grid_tube, sew
from kitsuke.metrics import penetration

from .conftest import flat_sheet, icosphere

N_AROUND, N_ROWS, SPACING = 24, 5, 0.02  # a tube 48 cm round (radius 7.6 cm), 8 cm tall


def _tube_laid_as_two_panels(gap_m: float) -> tuple[ClothModel, np.ndarray]:
    """A tube laid as GarmentCode lays a front and a back: two flat panels `gap_m` in front of and behind the
    origin (z), joined only by their two side seams, whose shared vertices lie halfway (z = 0), so the triangles
    next to the seams are stretched across the gap."""
    faces, corners, _ = grid_tube(N_AROUND, N_ROWS, SPACING)
    model = ClothModel.from_corners(faces, corners, n_vertices=N_AROUND * N_ROWS)
    i = np.arange(model.n_vertices) % N_AROUND
    j = np.arange(model.n_vertices) // N_AROUND
    half = N_AROUND // 2
    front = i <= half  # columns 0..12 in front, 12..24 (= 0) behind: columns 0 and 12 are the seams
    x = np.where(front, i - half / 2, 3 * half / 2 - i) * SPACING
    z = np.where(front, gap_m, -gap_m)
    z[(i == 0) | (i == half)] = 0.0
    return model, np.c_[x, (j - (N_ROWS - 1) / 2) * SPACING, z]


def _strain(model: ClothModel, x: np.ndarray) -> np.ndarray:
    e = model.edges
    return np.linalg.norm(x[e[:, 1]] - x[e[:, 0]], axis=1) / model.rest_lengths - 1.0


def test_sewing_closes_a_tube_laid_round_a_body_as_two_panels():
    body = icosphere(0.065, 3)
    collider = BodyCollider.from_mesh(body)
    model, x0 = _tube_laid_as_two_panels(gap_m=0.08)
    assert _strain(model, x0).max() > 2.0  # the seams' triangles start stretched across the 8 cm gap
    i = np.arange(model.n_vertices) % N_AROUND
    held = (i == N_AROUND // 4) | (i == 3 * N_AROUND // 4)  # each panel held at its middle, as by a stroke
    state = ClothState.new(model, x0.copy(), pinned=held)
    stats = sew(model, state, collider)
    x = state.positions
    assert 0 < stats.frames <= 90 and not stats.diverged
    assert stats.excess_m > 0.05
    np.testing.assert_array_equal(x[held], x0[held])
    assert np.abs(_strain(model, x)).max() < 0.05  # closed, at the pattern's lengths
    assert penetration(x, body).count == 0  # round the body, not through it
    # The seams closed at the body's sides, round it (radius 6.5 cm): each side's cloth out beyond it.
    for side in (0, N_AROUND // 2):
        assert (np.abs(x[i == side, 0]) > 0.06).all()
    assert state.velocities is None  # the static stages after it start at rest


def test_sewing_holds_pins_and_leaves_a_closed_garment_alone():
    collider = BodyCollider.from_mesh(icosphere(0.05, 2, centre=(0.0, 0.0, -0.5)))
    model, x0 = flat_sheet(8, 6, 0.02)
    state = ClothState.new(model, x0.copy())
    assert sew(model, state, collider).frames == 0  # nothing stretched: nothing done
    np.testing.assert_array_equal(state.positions, x0)
    stretched = x0 * np.array([2.0, 1.0, 1.0])
    pinned = np.zeros(model.n_vertices, dtype=bool)
    pinned[0] = True
    state = ClothState.new(model, stretched.copy(), pinned=pinned)
    stats = sew(model, state, collider, shrink_m=0.005)
    np.testing.assert_array_equal(state.positions[0], stretched[0])
    assert stats.frames > 0 and np.abs(_strain(model, state.positions)).max() < 0.05
    # At most shrink_m a frame: each 4 cm edge (2 cm at rest) starts at 4 / 1.02 cm, within the strain limit, and
    # reaches its rest length after ceil(1.92 / 0.5) = 4 frames (a jump would take 1).
    state = ClothState.new(model, stretched.copy())
    assert sew(model, state, collider, shrink_m=0.005, settle_frames=1).frames == 4
