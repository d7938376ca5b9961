"""The polish: its energy kernels against plain numpy and finite differences, the bending matrix's invariants,
the tethers' nearest points, and compressed cloth that buckles out of plane instead of staying compressed."""

from __future__ import annotations

import numpy as np
import pytest

from kitsuke.cloth import BodyCollider, ClothState, Tethers, bending_matrix, folded_faces, polish
from kitsuke.cloth._polish import plane_energy, stretch_energy, tether_energy
from kitsuke.errors import InputError
from kitsuke.metrics import strain

from .conftest import flat_sheet


def numeric_gradient(f, x: np.ndarray, h: float = 1e-7) -> np.ndarray:
    g = np.zeros_like(x)
    for i in np.ndindex(x.shape):
        xp, xm = x.copy(), x.copy()
        xp[i] += h
        xm[i] -= h
        g[i] = (f(xp) - f(xm)) / (2 * h)
    return g


def wobbled_sheet(seed: int = 0):
    model, rest = flat_sheet(5, 4, 0.02)
    x = rest + np.random.default_rng(seed).normal(scale=0.003, size=rest.shape)
    return model, rest, x


def test_stretch_energy_matches_numpy_and_its_gradient_is_exact():
    model, _, x = wobbled_sheet()
    e, L = model.edges, model.rest_lengths
    g = np.zeros_like(x)
    total = stretch_energy(x, e, L, 20.0, 1000.0, 0.02, g)
    s = np.linalg.norm(x[e[:, 0]] - x[e[:, 1]], axis=1) / L - 1
    reference = (L * (20.0 * s**2 + 1000.0 * np.maximum(np.abs(s) - 0.02, 0) ** 2)).sum()
    assert total == pytest.approx(reference, rel=1e-12)
    assert (np.abs(s) > 0.02).any()  # the barrier is exercised

    def f(y):
        return stretch_energy(y, e, L, 20.0, 1000.0, 0.02, np.zeros_like(y))

    np.testing.assert_allclose(g, numeric_gradient(f, x), atol=1e-5 * np.abs(g).max())


def test_contact_and_tether_gradients_are_exact():
    model, _, x = wobbled_sheet(1)
    idx = np.arange(0, len(x), 2)
    points = np.zeros((len(idx), 3))
    normals = np.tile([0.0, 0.0, 1.0], (len(idx), 1))
    g = np.zeros_like(x)
    total = plane_energy(x, idx, points, normals, 0.003, 1e4, g)
    assert total == pytest.approx(1e4 * (np.maximum(0.003 - x[idx, 2], 0) ** 2).sum())
    np.testing.assert_allclose(
        g, numeric_gradient(lambda y: plane_energy(y, idx, points, normals, 0.003, 1e4, np.zeros_like(y)), x), atol=1e-6
    )
    tri = model.faces[:4]
    bary = np.full((4, 3), 1 / 3)
    targets = np.einsum("nk,nkc->nc", bary, x[tri]) + [0.0, 0.01, 0.0]
    g = np.zeros_like(x)
    tether_energy(x, tri, bary, targets, 0.004, 1e3, g)
    np.testing.assert_allclose(
        g, numeric_gradient(lambda y: tether_energy(y, tri, bary, targets, 0.004, 1e3, np.zeros_like(y)), x), atol=1e-6
    )


def test_bending_is_zero_on_flat_cloth_and_grows_with_the_fold_angle_squared():
    model, rest = flat_sheet(6, 6, 0.02)
    Q = bending_matrix(model)
    np.testing.assert_allclose(Q @ rest, 0.0, atol=1e-9)
    # Any placement in a plane is flat too: rotate the sheet.
    c, s = np.cos(0.7), np.sin(0.7)
    turned = rest @ np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]]).T + [0.1, 0.2, 0.3]
    assert abs(np.einsum("ij,ij->", turned, Q @ turned)) < 1e-9 * np.einsum("ij,ij->", turned, abs(Q) @ abs(turned))

    def folded(angle: float) -> float:
        """The sheet folded along the line x = 5 cm (a hinge row) by `angle` radians."""
        p = rest.copy()
        right = p[:, 0] > 0.05 + 1e-9
        d = p[right, 0] - 0.05
        p[right, 0] = 0.05 + d * np.cos(angle)
        p[right, 2] = d * np.sin(angle)
        return float(np.einsum("ij,ij->", p, Q @ p))

    small, double = folded(0.1), folded(0.2)
    assert small > 0 and double / small == pytest.approx(4.0, rel=0.02)


def test_tethers_nearest_is_the_closest_polyline_point():
    model, rest = flat_sheet(5, 4, 0.02)
    line = np.array([[0.0, 0.1, 0.05], [0.05, 0.1, 0.02], [0.1, 0.12, 0.0]])
    faces = np.arange(model.n_faces)
    tethers = Tethers.from_polylines([(faces, np.full((len(faces), 3), 1 / 3), line)], model.faces, 0.01)
    got = tethers.nearest(rest)
    t = np.linspace(0, 1, 2001)[:, None]
    dense = np.concatenate([line[i] + t * (line[i + 1] - line[i]) for i in range(len(line) - 1)])
    p = np.einsum("nk,nkc->nc", tethers.bary, rest[tethers.tri])
    best = dense[np.argmin(np.linalg.norm(p[:, None] - dense[None], axis=2), axis=1)]
    np.testing.assert_allclose(np.linalg.norm(got - p, axis=1), np.linalg.norm(best - p, axis=1), atol=1e-4)


def floor_collider(size: float = 1.0) -> BodyCollider:
    """A closed box whose top face is the plane z = 0 (the 'body' the sheet lies on)."""
    import trimesh

    from kitsuke.geometry import TriMesh

    box = trimesh.creation.box(extents=(size, size, size))
    box.apply_translation((0.1, 0.1, -size / 2))
    return BodyCollider.from_mesh(TriMesh(np.asarray(box.vertices), np.asarray(box.faces), name="floor"))


def test_compressed_cloth_on_a_floor_buckles_up_instead_of_staying_compressed():
    """A sheet squeezed to 92 % of its rest size, lying on a floor: the polish lifts it into wrinkles (out of the
    floor, never into it) so that no edge stays squeezed past a few percent; pinned corners stay exactly still."""
    model, rest = flat_sheet(11, 11, 0.02)
    squeezed = rest * [0.92, 0.92, 0.0] + [0.0, 0.0, 0.003]
    squeezed[:, 2] += np.random.default_rng(2).normal(scale=2e-4, size=len(squeezed))  # break the symmetry
    corners = np.zeros(model.n_vertices, dtype=bool)
    corners[[0, model.n_vertices - 1]] = True
    state = ClothState.new(model, squeezed, pinned=corners)
    before = strain(state.positions, model.edges, model.rest_lengths)
    collider = floor_collider()
    stats = polish(model, state, collider, rounds=6, iterations=60)
    after = strain(state.positions, model.edges, model.rest_lengths)
    assert before.max > 0.07
    assert after.max < 0.05 and after.mean < 0.02
    assert stats.rounds == 6 and stats.iterations > 0
    assert state.positions[~corners, 2].min() > model.params.contact_offset_m - 1e-4  # kept the offset above the floor
    assert state.positions[:, 2].max() > 0.01  # it buckled up
    np.testing.assert_array_equal(state.positions[corners], squeezed[corners])
    assert stats.folded == folded_faces(model, state).sum()


def test_bad_arguments_are_rejected():
    model, rest = flat_sheet(4, 4, 0.02)
    state = ClothState.new(model, rest)
    with pytest.raises(InputError):
        polish(model, state, floor_collider(), rounds=-1)
    with pytest.raises(InputError):
        polish(model, state, floor_collider(), iterations=0)
    with pytest.raises(InputError):
        polish(model, state, None)
    from kitsuke.dressing import WrapParams

    with pytest.raises(InputError):
        WrapParams(polish_iterations=0)
    with pytest.raises(InputError):
        WrapParams(polish_rounds=-1)
