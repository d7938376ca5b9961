"""The polish: its energy kernels against plain numpy and finite differences, the bending matrix's invariants,
the tethers' nearest points, and compressed cloth that buckles out of plane instead of staying compressed."""

from __future__ import annotations

import numpy as np
import pytest

from kitsuke.cloth import BodyCollider, ClothState, Tethers, bending_stencil, folded_faces, polish, polish_refined
from kitsuke.cloth._lbfgs import minimise
from kitsuke.cloth._polish_energy import (
    bend_energy,
    layer_energy,
    plane_energy,
    polish_energy,
    stretch_energy,
    tether_energy,
)
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


def bending(model, x: np.ndarray, weight: float = 1.0) -> float:
    w, coef = bending_stencil(model)
    return bend_energy(x, model.hinges, w, weight * coef, np.zeros_like(x))


def test_bending_is_zero_on_flat_cloth_and_grows_with_the_fold_angle_squared():
    model, rest = flat_sheet(6, 6, 0.02)
    assert abs(bending(model, rest)) < 1e-12
    # Any placement in a plane is flat too: rotate the sheet.
    c, s = np.cos(0.7), np.sin(0.7)
    turned = rest @ np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]]).T + [0.1, 0.2, 0.3]
    assert abs(bending(model, turned)) < 1e-9

    def folded(angle: float) -> float:
        """The sheet folded along the line x = 5 cm (a hinge row) by `angle` radians."""
        p = rest.copy()
        right = p[:, 0] > 0.05 + 1e-9
        d = p[right, 0] - 0.05
        p[right, 0] = 0.05 + d * np.cos(angle)
        p[right, 2] = d * np.sin(angle)
        return bending(model, p)

    small, double = folded(0.1), folded(0.2)
    assert small > 0 and double / small == pytest.approx(4.0, rel=0.02)


def test_bending_matches_numpy_and_its_gradient_is_exact():
    model, _, x = wobbled_sheet(2)
    w, coef = bending_stencil(model)
    k = np.einsum("hi,hic->hc", w, x[model.hinges])
    g = np.zeros_like(x)
    assert bend_energy(x, model.hinges, w, coef, g) == pytest.approx((coef * (k**2).sum(axis=1)).sum(), rel=1e-12)
    np.testing.assert_allclose(g, numeric_gradient(lambda y: bending(model, y), x), atol=1e-6 * np.abs(g).max())


def sheet_terms(model, x: np.ndarray):
    """Every term of the polish's energy on a wobbled sheet: contact planes under half the vertices, one layer
    plane, one tether."""
    idx = np.arange(0, len(x), 2)
    w, coef = bending_stencil(model)
    tri = np.ascontiguousarray(model.faces[:1])
    bary = np.full((1, 3), 1 / 3)
    return (
        model.edges, model.rest_lengths, 20.0, 1000.0, 0.02,
        model.hinges, w, 1e-3 * coef,
        idx, np.zeros((len(idx), 3)), np.tile([0.0, 0.0, 1.0], (len(idx), 1)), 0.003, 1e4,
        np.array([len(x) - 1]), np.ascontiguousarray(model.faces[-2:-1]), bary, np.array([[0.0, 0.0, 1.0]]), 0.002, 1e4,
        tri, bary, np.einsum("nk,nkc->nc", bary, x[tri]) + [0.0, 0.01, 0.0], 0.004, 1e3,
    )  # fmt: skip


def test_polish_energy_is_the_sum_of_its_terms():
    model, _, x = wobbled_sheet(3)
    t = sheet_terms(model, x)
    z = np.zeros_like(x)
    parts = (
        stretch_energy(x, *t[0:5], z.copy())
        + bend_energy(x, *t[5:8], z.copy())
        + plane_energy(x, *t[8:13], z.copy())
        + layer_energy(x, *t[13:19], z.copy())
        + tether_energy(x, *t[19:24], z.copy())
    )
    g = np.full_like(x, 7.0)  # overwritten, not added to
    assert polish_energy(x, g, t) == pytest.approx(parts, rel=1e-12)
    np.testing.assert_allclose(
        g, numeric_gradient(lambda y: polish_energy(y, np.zeros_like(y), t), x), atol=1e-5 * np.abs(g).max()
    )


def test_lbfgs_finds_the_minimum_and_leaves_held_vertices_alone():
    """On a stretched and wobbled sheet with one edge row held: the energy falls to a stationary point (gradient
    of the free vertices near zero, far below the start's), the held vertices do not move, and more iterations
    never end higher."""
    model, rest = flat_sheet(7, 6, 0.02)
    x0 = rest * [1.06, 1.0, 1.0] + np.random.default_rng(4).normal(scale=0.002, size=rest.shape)
    x0[:, 2] += 0.01
    t = sheet_terms(model, x0)
    held = np.flatnonzero(rest[:, 0] < 1e-9)
    free = np.setdiff1d(np.arange(len(x0)), held)
    g0 = np.zeros_like(x0)
    e0 = polish_energy(x0, g0, t)
    ends = []
    for iterations in (10, 400):
        x = x0.copy()
        energy, done, evaluations = minimise(x, free, iterations, 20, t)
        assert done <= iterations and evaluations >= done
        np.testing.assert_array_equal(x[held], x0[held])
        g = np.zeros_like(x)
        assert polish_energy(x, g, t) == pytest.approx(energy, rel=1e-12)
        ends.append((energy, np.abs(g[free]).max()))
    assert ends[1][0] <= ends[0][0] < e0
    assert ends[1][1] < 1e-3 * np.abs(g0[free]).max()
    # Nothing free: nothing moves, nothing fails.
    x = x0.copy()
    minimise(x, np.zeros(0, dtype=np.int64), 10, 20, t)
    np.testing.assert_array_equal(x, x0)


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


def test_strain_limit_takes_stretch_out_or_leaves_the_cloth_as_it_was():
    """cap_strain pulls the few edges strained past the limit back to it; where the limit cannot win (a strip
    stretched 15 % between pinned ends: the sweeps can only move the strain about, raising its max), it leaves the
    cloth exactly as it found it and says so."""
    from kitsuke.cloth._polish import cap_strain

    model, rest = flat_sheet(11, 6, 0.02)
    lifted = rest + [0.0, 0.0, 0.003]
    bumped = lifted.copy()
    bumped[27] += [0.004, 0.003, 0.0]  # an inner vertex pulled 5 mm: its edges 20-30 % long
    state = ClothState.new(model, bumped)
    assert strain(bumped, model.edges, model.rest_lengths).max > 0.2
    assert cap_strain(model, state, floor_collider(), 0.045, sweeps=400)
    assert strain(state.positions, model.edges, model.rest_lengths).max < 0.046

    pulled = rest * [1.15, 1.0, 0.0] + [0.0, 0.0, 0.003]
    ends = (rest[:, 0] < 1e-9) | (rest[:, 0] > rest[:, 0].max() - 1e-9)
    state = ClothState.new(model, pulled, pinned=ends)
    assert not cap_strain(model, state, floor_collider(), 0.045, sweeps=400)
    np.testing.assert_array_equal(state.positions, pulled)


def test_bad_arguments_are_rejected():
    model, rest = flat_sheet(4, 4, 0.02)
    state = ClothState.new(model, rest)
    with pytest.raises(InputError):
        polish(model, state, floor_collider(), rounds=-1)
    with pytest.raises(InputError):
        polish(model, state, floor_collider(), iterations=0)
    with pytest.raises(InputError):
        polish(model, state, None)
    from kitsuke.dressing import PolishSettings, WrapParams

    for bad in ({"iterations": 0}, {"rounds": -1}, {"levels": -1}, {"refine_iterations": 0}, {"limit_sweeps": -1}):
        with pytest.raises(InputError, match="PolishSettings"):
            PolishSettings(**bad)
        with pytest.raises(InputError, match="PolishSettings"):
            WrapParams().changed({f"polish.{k}": v for k, v in bad.items()})
    for limit in (-0.01, 1.0, float("nan")):
        with pytest.raises(InputError, match="strain_limit"):
            WrapParams().changed({"polish.strain_limit": limit})
    with pytest.raises(InputError, match="levels"):
        polish_refined(model, state, floor_collider(), levels=-1)
    with pytest.raises(InputError, match="strain_limit"):
        polish_refined(model, state, floor_collider(), strain_limit=2.0)


def test_layer_energy_matches_numpy_and_its_gradient_is_exact():
    """Each layered vertex's penalty for lying less than the gap along its normal from its point on the other
    layer's face; the face's corners share the gradient by their barycentric weights."""
    model, _, x = wobbled_sheet(3)
    rng = np.random.default_rng(4)
    vertex = np.array([0, 7, 12, 19], dtype=np.int64)
    tri = np.ascontiguousarray(model.faces[[5, 9, 2, 14]])
    bary = rng.dirichlet(np.ones(3), size=4)
    normals = rng.normal(size=(4, 3))
    normals /= np.linalg.norm(normals, axis=1)[:, None]
    gap, weight = 0.004, 50.0

    def numpy_energy(xx):
        q = np.einsum("jk,jkc->jc", bary, xx[tri])
        h = np.einsum("jc,jc->j", xx[vertex] - q, normals)
        return weight * (np.maximum(gap - h, 0.0) ** 2).sum()

    g = np.zeros_like(x)
    total = layer_energy(x, vertex, tri, bary, normals, gap, weight, g)
    assert total == pytest.approx(numpy_energy(x), rel=1e-12) and total > 0
    np.testing.assert_allclose(g, numeric_gradient(numpy_energy, x), atol=1e-6)


def test_polish_keeps_squeezed_layers_in_order():
    """Two layered sheets lying on a floor, the upper one 2 mm over the lower, both squeezed to 90 %: the polish
    buckles them and, with the layers in its energy, the upper sheet stays over the lower one wherever it lies
    above it (no vertex more than half a millimetre under)."""
    from kitsuke.cloth import ClothModel, ClothParams, grid_sheet

    uv, f = grid_sheet(9, 9, 0.02)
    nv = len(uv)
    faces = np.concatenate([f, f + nv])
    layer = np.r_[np.ones(len(f), dtype=np.int8), np.full(len(f), 2, dtype=np.int8)]
    model = ClothModel.from_corners(faces, np.concatenate([uv[f], uv[f]]), params=ClothParams(), face_layer=layer)
    lower = np.c_[uv * 0.9, np.full(nv, 0.0012)]
    upper = np.c_[uv * 0.9 + 0.004, np.full(nv, 0.0032)]
    pos = np.concatenate([lower, upper])
    pos[:, 2] += np.random.default_rng(5).normal(scale=2e-4, size=len(pos))
    state = ClothState.new(model, pos)
    polish(model, state, floor_collider(), rounds=6, iterations=60)
    x = state.positions
    # They buckled: nothing is left squeezed (flat, every edge would be 10 % short) and the sheets rose.
    assert strain(x, model.edges, model.rest_lengths).max < 0.01 and x[:, 2].max() > 0.004
    import igl

    under = faces[layer == 1]
    top = np.arange(nv, 2 * nv)
    d2, fi, cp = igl.point_mesh_squared_distance(x[top], x, under)
    n = np.cross(x[under[fi, 1]] - x[under[fi, 0]], x[under[fi, 2]] - x[under[fi, 0]])
    n /= np.linalg.norm(n, axis=1)[:, None]
    h = np.einsum("ij,ij->i", x[top] - cp, n)
    over = d2 - h * h < 1e-8  # above the lower sheet, not beside it
    assert over.sum() > 40 and h[over].min() > -5e-4


def test_polish_refined_refines_round_a_fold_it_cannot_open():
    """A triangle folded over its neighbours with its corners pinned: the polish cannot open it, so each level
    refines the cloth round it; the corner data is carried exactly (here the pattern positions themselves) and each
    new face lies where the face it came from (parent_face) lay in the pattern."""
    model, rest = flat_sheet(8, 8, 0.02)
    x = rest.copy()
    x[:, 2] = 0.003
    f = model.faces[40]
    x[f[0]] = x[f[1]] + x[f[2]] - x[f[0]]  # corner 0 reflected over the opposite edge: folded
    pinned = np.zeros(model.n_vertices, dtype=bool)
    pinned[f] = True
    state = ClothState.new(model, x, pinned=pinned)
    assert folded_faces(model, state).any()
    r = polish_refined(
        model, state, floor_collider(), rounds=2, iterations=10, levels=2, corner_data={"uv": model.rest_corners}
    )
    assert r.levels == 2 and r.model.n_faces > model.n_faces and r.model.n_vertices > model.n_vertices
    np.testing.assert_allclose(r.corner_data["uv"], r.model.rest_corners, atol=1e-15)
    # Each new face lies in the face it came from or, made by an edge flip, partly in the one across that edge.
    near = np.c_[np.arange(model.n_faces), model.face_adjacency][r.parent_face]  # (F', 4)
    inside = np.zeros(r.model.n_faces, dtype=bool)
    centroid = r.model.rest_corners.mean(axis=1)
    for k in range(4):
        tri = model.rest_corners[np.maximum(near[:, k], 0)]
        e1, e2, d = tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0], centroid - tri[:, 0]
        det = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]
        u = (d[:, 0] * e2[:, 1] - d[:, 1] * e2[:, 0]) / det
        v = (e1[:, 0] * d[:, 1] - e1[:, 1] * d[:, 0]) / det
        inside |= (near[:, k] >= 0) & (np.minimum(np.minimum(u, v), 1 - u - v) > -1e-9)
    assert inside.all()
    np.testing.assert_array_equal(r.state.positions[f], x[f])  # pins held
    assert len(r.state.pinned) == r.model.n_vertices and not r.state.pinned[model.n_vertices :].any()
    # Without levels nothing is refined.
    r0 = polish_refined(model, ClothState.new(model, x, pinned=pinned), floor_collider(), rounds=1, levels=0)
    assert r0.levels == 0 and r0.model is model
