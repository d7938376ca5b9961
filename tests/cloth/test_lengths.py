"""Edge-length restoration: stretched cloth goes back to its rest lengths, pins and inactive cloth stay exactly
still, and collision keeps it out of the body while it does."""

from __future__ import annotations

import numpy as np
import pytest

from kitsuke.cloth import ClothState, Tethers, restore_lengths
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


def test_over_relaxation_gets_further_in_the_same_sweeps():
    """A long sheet stretched 15 % with one end pinned: in 300 sweeps the over-relaxed restoration (omega 1.5, the
    last 100 sweeps plain) takes out clearly more of the strain than plain Gauss-Seidel; pins hold; with no more
    sweeps than the plain finish it is plain Gauss-Seidel, bit for bit."""
    model, rest = flat_sheet(30, 4, 0.02, gravity_step_m=0.0)
    stretched = rest * [1.15, 1.0, 1.0]
    pins = rest[:, 0] == 0.0
    result = {}
    for omega in (1.0, 1.5):
        for sweeps in (100, 300):
            state = ClothState.new(model, stretched.copy(), pinned=pins)
            restore_lengths(model, state, sweeps=sweeps, over_relaxation=omega)
            np.testing.assert_array_equal(state.positions[pins], stretched[pins])
            result[omega, sweeps] = state.positions
    s = {o: strain(result[o, 300], model.edges, model.rest_lengths) for o in (1.0, 1.5)}
    assert s[1.5].max < 0.6 * s[1.0].max and s[1.5].mean < 0.5 * s[1.0].mean
    np.testing.assert_array_equal(result[1.0, 100], result[1.5, 100])
    for bad in (0.9, 2.0, float("nan")):
        with pytest.raises(InputError, match="over_relaxation"):
            restore_lengths(model, ClothState.new(model, stretched.copy()), sweeps=1, over_relaxation=bad)


def test_chebyshev_acceleration_gets_further_than_over_relaxation():
    """The same long sheet: 300 Chebyshev-accelerated sweeps (rho 0.99, the wrap's) take out more of the strain
    than 300 over-relaxed ones, pins stay exactly still, and nothing overshoots into a worse state than plain
    Gauss-Seidel; rho outside (0, 1) is refused."""
    model, rest = flat_sheet(30, 4, 0.02, gravity_step_m=0.0)
    stretched = rest * [1.15, 1.0, 1.0]
    pins = rest[:, 0] == 0.0
    result = {}
    for name, kw in {"plain": {}, "sor": {"over_relaxation": 1.5}, "chebyshev": {"chebyshev_rho": 0.99}}.items():
        state = ClothState.new(model, stretched.copy(), pinned=pins)
        restore_lengths(model, state, sweeps=300, **kw)
        np.testing.assert_array_equal(state.positions[pins], stretched[pins])
        assert np.isfinite(state.positions).all()
        result[name] = strain(state.positions, model.edges, model.rest_lengths)
    assert result["chebyshev"].mean < 0.5 * result["sor"].mean < result["plain"].mean
    assert result["chebyshev"].max < result["sor"].max
    for bad in (0.0, 1.0, float("nan")):
        with pytest.raises(InputError, match="chebyshev_rho"):
            restore_lengths(model, ClothState.new(model, stretched.copy()), sweeps=1, chebyshev_rho=bad)


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


def line_distance(points: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(n,) distance of points (n, 3) to the segment a-b."""
    t = np.clip((points - a) @ (b - a) / ((b - a) @ (b - a)), 0.0, 1.0)
    return np.linalg.norm(points - (a + t[:, None] * (b - a)), axis=1)


def right_edge_tethers(model, rest, line: np.ndarray, reach_m: float) -> tuple[Tethers, np.ndarray]:
    """Tethers on the centres of the triangles touching the sheet's right column, to `line` (2, 3); and the
    triangles' vertex indices (n, 3)."""
    right = np.flatnonzero(np.isclose(rest[:, 0], rest[:, 0].max()))
    faces = np.flatnonzero(np.isin(model.faces, right).any(axis=1))
    bary = np.full((len(faces), 3), 1.0 / 3.0)
    return Tethers.from_polylines([(faces, bary, line)], model.faces, reach_m), model.faces[faces]


def test_tethers_lift_the_free_edge_to_its_line_without_stretching_the_sheet():
    """The left column pinned, the right edge tethered (5 mm reach) to a line 5 cm up, where the edge comes when
    the sheet turns about its pins (a turn costs no edge length): every tethered point ends within reach, and
    the sheet keeps its rest lengths."""
    model, rest = flat_sheet(12, 10, 0.02, gravity_step_m=0.0)
    r, y1 = rest[:, 0].max() - 0.01, rest[:, 1].max()  # the tethered triangle centres lie 0.3-0.7 cm in
    x = np.sqrt(r**2 - 0.05**2)
    line = np.array([[x, 0.0, 0.05], [x, y1, 0.05]])
    tethers, tri = right_edge_tethers(model, rest, line, 0.005)
    pins = rest[:, 0] == 0.0
    state = ClothState.new(model, rest.copy(), pinned=pins)
    stats = restore_lengths(model, state, sweeps=600, tethers=tethers)
    points = np.einsum("ij,ijk->ik", tethers.bary, state.positions[tri])
    assert line_distance(points, *line).max() <= 0.005 + 2e-4
    assert stats.worst_tether_m < 2e-4
    assert strain(state.positions, model.edges, model.rest_lengths).max < 0.02
    np.testing.assert_array_equal(state.positions[pins], rest[pins])
    assert state.positions[:, 2].max() > 0.04  # it did lift


def test_tethers_within_reach_change_nothing():
    """A one-sided constraint: a stretched sheet whose tethered points stay within reach of their line all along
    ends bit-identical to the same restoration without tethers."""
    model, rest = flat_sheet(8, 6, 0.02, gravity_step_m=0.0)
    stretched = rest * [1.1, 1.0, 1.0]
    x1, y1 = stretched[:, 0].max(), stretched[:, 1].max()
    tethers, _ = right_edge_tethers(model, rest, np.array([[x1, 0.0, 0.0], [x1, y1, 0.0]]), 0.5)
    pins = rest[:, 0] == 0.0
    free, held = ClothState.new(model, stretched, pinned=pins), ClothState.new(model, stretched, pinned=pins)
    restore_lengths(model, free, sweeps=50)
    stats = restore_lengths(model, held, sweeps=50, tethers=tethers)
    np.testing.assert_array_equal(held.positions, free.positions)
    assert stats.worst_tether_m == 0.0


def test_a_band_limits_strain_instead_of_restoring_rest_lengths():
    """band 0.04: a sheet stretched 10 % (one corner held) ends with every edge within 4 % of its rest length and
    most of them right at the limit, not back at rest (as without a band). (Plain sweeps converge slowly on a
    uniform stretch: 300 leave 4.4 %.)"""
    model, rest = flat_sheet(8, 8, 0.02)
    pins = np.zeros(model.n_vertices, dtype=bool)
    pins[0] = True
    limited = ClothState.new(model, rest * 1.1, pinned=pins)
    stats = restore_lengths(model, limited, sweeps=3000, band=0.04, tolerance_m=1e-9)
    s = strain(limited.positions, model.edges, model.rest_lengths)
    assert s.max <= 0.04 + 1e-6 and np.median(s.per_edge) > 0.035
    assert stats.sweeps < 3000  # stopped once nothing was beyond the band (measured: 1342 sweeps)
    free = ClothState.new(model, rest * 1.1, pinned=pins)
    restore_lengths(model, free, sweeps=3000)
    assert np.median(strain(free.positions, model.edges, model.rest_lengths).per_edge) < 0.5 * np.median(s.per_edge)


def test_bad_arguments_are_rejected():
    model, rest = flat_sheet(4, 4, 0.02)
    state = ClothState.new(model, rest)
    for kw in (dict(band=-0.01), dict(band=1.0), dict(band=float("nan"))):
        with pytest.raises(InputError, match="band"):
            restore_lengths(model, state, **kw)
    for kw in (dict(sweeps=-1), dict(collide_every=0), dict(tolerance_m=float("nan"))):
        with pytest.raises(InputError):
            restore_lengths(model, state, **kw)
    with pytest.raises(InputError):
        restore_lengths(model, rest)
    with pytest.raises(InputError, match="tethers must be"):
        restore_lengths(model, state, tethers="strokes")
    line = np.zeros((2, 3))
    other, _ = flat_sheet(8, 8, 0.02)
    with pytest.raises(InputError, match="vertices the model does not have"):
        restore_lengths(model, state, tethers=Tethers.from_polylines([([60], [[1, 0, 0]], line)], other.faces, 0.01))
    with pytest.raises(InputError, match="reach"):
        Tethers.from_polylines([([0], [[1, 0, 0]], line)], model.faces, 0.0)


def _pulled_apart_sheet():
    """A sheet pinned on its left column whose right column is tethered to a line 30 cm past where the cloth can
    reach: the edges and the tethers cannot both be met."""
    model, rest = flat_sheet(30, 10, 0.02, gravity_step_m=0.0)
    pins = rest[:, 0] == 0.0
    right = np.flatnonzero(rest[:, 0] == rest[:, 0].max())
    face = np.array([np.flatnonzero((model.faces == v).any(axis=1))[0] for v in right])
    bary = (model.faces[face] == right[:, None]).astype(float)
    tethers = Tethers.from_polylines([(face, bary, np.array([[0.9, -1.0, 0.0], [0.9, 1.0, 0.0]]))], model.faces, 0.001)
    return model, rest, pins, tethers


def test_accelerated_sweeps_that_run_away_are_run_again_plain():
    """Chebyshev extrapolation fighting tethers can grow without bound (GarmentCode's shirt on strokes drawn from
    its placement reached 1e18 m); such a run is detected and done again from the start, plain, with the very
    result of a plain run."""
    model, rest, pins, tethers = _pulled_apart_sheet()
    fast = ClothState.new(model, rest.copy(), pinned=pins)
    stats = restore_lengths(model, fast, sweeps=400, tethers=tethers, chebyshev_rho=0.9999, over_relaxation=1.9)
    assert stats.restarted
    plain = ClothState.new(model, rest.copy(), pinned=pins)
    assert not restore_lengths(model, plain, sweeps=400, tethers=tethers).restarted
    np.testing.assert_array_equal(fast.positions, plain.positions)
    assert np.isfinite(fast.positions).all() and np.abs(fast.positions).max() < 1.0


def test_sweeps_that_run_away_even_plain_raise_a_computation_error():
    """Rest lengths a hundred times the cloth's: every sweep throws vertices metres; nothing usable comes out."""
    from kitsuke.cloth import ClothModel
    from kitsuke.errors import ComputationError

    model, rest = flat_sheet(6, 6, 0.02, gravity_step_m=0.0)
    huge = ClothModel.from_corners(model.faces, rest[model.faces][..., :2] * 100.0, n_vertices=len(rest))
    state = ClothState.new(huge, rest.copy(), pinned=rest[:, 0] == 0.0)
    with pytest.raises(ComputationError, match="length restoration"):
        restore_lengths(huge, state, sweeps=50)
