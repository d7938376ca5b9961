"""Each relaxation kernel against its plain-numpy reference on small random cases."""

from __future__ import annotations

import numpy as np
import pytest

from kitsuke.cloth import ClothParams, Tethers
from kitsuke.cloth import _kernels as K

from . import reference as ref
from .conftest import flat_sheet

#: Kernels and references do the same arithmetic in a different order or method: agreement to 1e-9 m.
ATOL = 1e-9


@pytest.fixture
def crumpled(rng):
    """A 6 x 5 sheet with its vertices jittered out of the plane by about a third of an edge."""
    model, pos = flat_sheet(6, 5, 0.02)
    pos = pos + rng.normal(0, 0.006, pos.shape)
    return model, np.ascontiguousarray(pos)


def test_reference_normals_match(crumpled, rng):
    model, pos = crumpled
    pos[model.faces[3]] = pos[model.faces[3]][[0, 2, 1]]  # fold one triangle over its neighbours
    active = rng.random(model.n_faces) > 0.2
    nf = model.n_faces
    out_n, out_ref, out_f = np.zeros((nf, 3)), np.zeros((nf, 3)), np.zeros(nf, dtype=np.uint8)
    for unflip in (True, False):
        K.reference_normals(
            pos, model.faces, model.face_adjacency, model.face_adjacency_sign, active, unflip, out_n, out_ref, out_f
        )
        n, r, f = ref.reference_normals(
            pos, model.faces, model.face_adjacency, model.face_adjacency_sign, active, unflip
        )
        np.testing.assert_allclose(out_n, n, atol=ATOL)
        np.testing.assert_allclose(out_ref, r, atol=ATOL)
        np.testing.assert_array_equal(out_f.astype(bool), f)
    assert out_f.any()


def test_shape_match_goals_match(crumpled, rng):
    model, pos = crumpled
    active = rng.random(model.n_faces) > 0.2
    # Reference normals: mostly own normals, some random unit vectors (the un-flip case projects off-plane).
    tri = pos[model.faces]
    n = ref.unit(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]))
    some = rng.random(model.n_faces) < 0.3
    n[some] = ref.unit(rng.normal(size=(some.sum(), 3)))
    out = np.zeros((model.n_faces, 3, 3))
    K.shape_match_goals(pos, model.faces, model.rest_corners, n, active, out)
    want = ref.shape_match_goals(pos, model.faces, model.rest_corners, n, active)
    np.testing.assert_allclose(out[active], want[active], atol=ATOL)
    # Goals are congruent to the rest triangles.
    g = out[active]
    rest = model.rest_corners[active]
    for k in range(3):
        glen = np.linalg.norm(g[:, (k + 1) % 3] - g[:, k], axis=1)
        rlen = np.linalg.norm(rest[:, (k + 1) % 3] - rest[:, k], axis=1)
        np.testing.assert_allclose(glen, rlen, atol=ATOL)


def test_hinge_deltas_match(crumpled, rng):
    model, pos = crumpled
    active = rng.random(model.n_faces) > 0.1
    out = np.zeros((len(model.hinges), 4, 3))
    K.hinge_deltas(pos, model.hinges, model.hinge_faces, active, out)
    want = ref.hinge_deltas(pos, model.hinges, model.hinge_faces, active)
    np.testing.assert_allclose(out, want, atol=ATOL)
    # The moves sum to zero (the hinge's centre stays), and the wings' own moves flatten it: 180 degrees.
    np.testing.assert_allclose(out.sum(axis=1), 0.0, atol=ATOL)
    h = int(np.argmax(np.abs(out).sum(axis=(1, 2))))
    a, b, c, d = model.hinges[h]
    p = pos.copy()
    p[[c, d]] += out[h, 2:]
    e = p[b] - p[a]
    cp = p[c] - p[a] - ((p[c] - p[a]) @ e) / (e @ e) * e
    dp = p[d] - p[a] - ((p[d] - p[a]) @ e) / (e @ e) * e
    assert ref.unit(cp) @ ref.unit(dp) == pytest.approx(-1.0, abs=1e-9)


def test_gather_moves_match(crumpled, rng):
    model, pos = crumpled
    p = ClothParams(stretch_stiffness=0.9, bend_stiffness=0.3, gravity_step_m=0.001, friction=0.5, max_step_m=0.004)
    nf, nv = model.n_faces, model.n_vertices
    active = rng.random(nf) > 0.2
    goals = pos[model.faces] + rng.normal(0, 0.003, (nf, 3, 3))
    hinge = rng.normal(0, 0.002, (len(model.hinges), 4, 3))
    pinned = rng.random(nv) < 0.1
    face = np.where(rng.random(nv) < 0.5, 0, -1)
    dist = rng.uniform(0, 0.01, nv)
    normal = ref.unit(rng.normal(size=(nv, 3)))
    out, step = np.zeros((nv, 3)), np.zeros(nv)
    K.gather_moves(
        pos,
        goals,
        hinge,
        model.vertex_corners_ptr,
        model.vertex_corners,
        model.vertex_hinges_ptr,
        model.vertex_hinges,
        active,
        model.hinge_faces,
        pinned,
        face,
        dist,
        normal,
        p.stretch_stiffness,
        p.bend_stiffness,
        p.gravity_step_m,
        p.friction,
        p.contact_distance_m,
        p.max_step_m,
        out,
        step,
    )
    touching = (face >= 0) & (dist < p.contact_distance_m)
    want = ref.gather_moves(
        pos, goals, hinge, model.faces, model.hinges, model.hinge_faces, active, pinned, touching, normal, p
    )
    np.testing.assert_allclose(out, want, atol=ATOL)
    np.testing.assert_allclose(step, np.linalg.norm(want - pos, axis=1), atol=ATOL)
    assert step.max() == pytest.approx(p.max_step_m)  # the clamp was exercised


def test_support_order_and_limit_strain_match(crumpled, rng):
    model, pos = crumpled
    pos = pos * np.array([1.0, 1.3, 1.0])  # stretched 30 % along y: most vertical edges exceed the limit
    nv = model.n_vertices
    roots = rng.random(nv) < 0.1
    active = rng.random(nv) > 0.1
    by_height = rng.permutation(nv).astype(np.int64)
    order, rank = np.zeros(nv, dtype=np.int64), np.zeros(nv, dtype=np.int64)
    n = K.support_order(pos, roots, active, by_height, order, rank)
    assert (np.diff(pos[by_height, 1]) <= 0).all()
    want = ref.support_order(pos, roots, active)
    assert n == len(want)
    np.testing.assert_array_equal(np.sort(order[:n]), np.sort(want))  # ties in height may come in any order
    assert roots[order[: roots[active].sum()]].all() and not roots[order[roots[active].sum() : n]].any()
    np.testing.assert_array_equal(rank[order[:n]], np.arange(n))
    assert (rank[~active] == -1).all()
    movable = active & ~roots
    got = pos.copy()
    K.limit_strain(
        order,
        n,
        rank,
        movable,
        model.adjacency_ptr,
        model.adjacency,
        model.adjacency_edge,
        model.rest_lengths,
        0.01,
        got,
    )
    expect = ref.limit_strain(pos, order[:n], model.edges, model.rest_lengths, movable, 0.01)
    np.testing.assert_allclose(got, expect, atol=ATOL)
    assert not np.allclose(got, pos)
    np.testing.assert_array_equal(got[~movable], pos[~movable])


def test_project_lengths_matches_reference_and_keeps_fixed_vertices(crumpled, rng):
    model, pos = crumpled
    movable = rng.random(model.n_vertices) > 0.2
    order = rng.permutation(model.n_edges).astype(np.int64)
    for omega in (1.0, 1.5):
        got = pos.copy()
        worst = K.project_lengths(got, model.edges, model.rest_lengths, movable, order, omega, 0.0)
        expect, expect_worst = ref.project_lengths(pos, model.edges, model.rest_lengths, movable, order, omega)
        np.testing.assert_allclose(got, expect, atol=ATOL)
        assert worst == pytest.approx(expect_worst)
        np.testing.assert_array_equal(got[~movable], pos[~movable])
        # The last edge of the sweep ends at its rest length if one of its ends could move, or past it by half
        # its error when over-relaxed.
        last = order[-1]
        if movable[model.edges[last]].any():
            a, b = model.edges[last]
            before = pos.copy()
            K.project_lengths(before, model.edges, model.rest_lengths, movable, order[:-1], omega, 0.0)
            err = np.linalg.norm(before[b] - before[a]) - model.rest_lengths[last]
            expect_len = model.rest_lengths[last] + (1.0 - omega) * err
            assert np.linalg.norm(got[b] - got[a]) == pytest.approx(expect_len)


def test_project_lengths_with_a_band_limits_strain_only(crumpled, rng):
    """band > 0 (a strain limit): the kernel matches the reference; cloth whose every edge is within the band is
    left exactly as it is; the edge corrected last ends on the band's edge, not at its rest length."""
    model, pos = crumpled
    movable = rng.random(model.n_vertices) > 0.2
    order = rng.permutation(model.n_edges).astype(np.int64)
    band = 0.05
    got = pos.copy()
    worst = K.project_lengths(got, model.edges, model.rest_lengths, movable, order, 1.0, band)
    expect, expect_worst = ref.project_lengths(pos, model.edges, model.rest_lengths, movable, order, 1.0, band)
    np.testing.assert_allclose(got, expect, atol=ATOL)
    assert worst == pytest.approx(expect_worst) and worst > 0
    movable[model.edges[order[-1]]] = True  # the last edge can move: it must end on the band's edge
    got = pos.copy()
    K.project_lengths(got, model.edges, model.rest_lengths, movable, order, 1.0, band)
    a, b = model.edges[order[-1]]
    before = pos.copy()
    K.project_lengths(before, model.edges, model.rest_lengths, movable, order[:-1], 1.0, band)
    s_before = np.linalg.norm(before[b] - before[a]) / model.rest_lengths[order[-1]] - 1
    s_after = np.linalg.norm(got[b] - got[a]) / model.rest_lengths[order[-1]] - 1
    if abs(s_before) > band:
        assert s_after == pytest.approx(np.sign(s_before) * band)
    else:  # within the band already: left alone
        assert s_after == pytest.approx(s_before)
    # The flat rest shape grown by 3 % everywhere: every edge within 5 %, nothing moves.
    flat = model.rest_corners.reshape(-1, 2)
    rest_pos = np.zeros((model.n_vertices, 3))
    rest_pos[model.faces.reshape(-1), :2] = flat * 1.03
    uniform = np.abs(np.linalg.norm(np.diff(rest_pos[model.edges], axis=1)[:, 0], axis=1) / model.rest_lengths - 1.03)
    assert uniform.max() < 1e-9  # one flat piece: its corners agree on each vertex
    kept = rest_pos.copy()
    assert K.project_lengths(kept, model.edges, model.rest_lengths, movable, order, 1.0, band) == 0.0
    np.testing.assert_array_equal(kept, rest_pos)


def test_stamped_sweeps_skip_only_what_cannot_change(crumpled, rng):
    """`project_band` and the tethers with stamps (what `restore_lengths` runs for a strain limit) give the plain
    sweeps' positions and worst errors bit for bit, over forward and backward sweeps with some vertices moved from
    outside between them (a collision), while skipping most of the work once the cloth is nearly within band."""
    model, pos = crumpled
    movable = rng.random(model.n_vertices) > 0.2
    forward = rng.permutation(model.n_edges).astype(np.int64)
    backward = np.ascontiguousarray(forward[::-1])
    faces = rng.integers(0, model.n_faces, 30)
    line = pos.mean(axis=0) + rng.normal(0.0, 0.03, (5, 3))
    groups = [(faces, rng.dirichlet(np.ones(3), 30), line)]
    plain_t, stamped_t = (Tethers.from_polylines(groups, model.faces, reach_m=0.02) for _ in range(2))
    plain, stamped = pos.copy(), pos.copy()
    moved, seen = np.zeros(model.n_vertices, np.int64), np.full(model.n_edges, -1, np.int64)
    clock = np.zeros(1, np.int64)
    stamps = (moved, np.full(len(stamped_t), -1, np.int64), clock)
    for sweep in range(40):
        order = backward if sweep % 2 else forward
        worst = K.project_lengths(plain, model.edges, model.rest_lengths, movable, order, 1.0, 0.05)
        met = clock[0]
        got = K.project_band(stamped, model.edges, model.rest_lengths, movable, order, 0.05, moved, seen, clock)
        assert got == worst
        assert stamped_t.project(stamped, movable, stamps) == plain_t.project(plain, movable)
        np.testing.assert_array_equal(stamped, plain)
        if sweep % 8 == 7:  # a collision pushes a few vertices: they are met again
            push = np.flatnonzero(movable)[rng.integers(0, movable.sum(), 5)]
            shift = rng.normal(0.0, 0.002, (5, 3))
            plain[push] += shift
            stamped[push] += shift
            clock[0] += 1
            moved[push] = clock[0]
    # Cloth within its band but for one vertex: after the first sweep meets every edge, the next meets only the
    # edges round what moved.
    flat = np.zeros((model.n_vertices, 3))
    flat[model.faces.reshape(-1), :2] = model.rest_corners.reshape(-1, 2) * 1.03
    flat[0] += 0.01
    moved[:], seen[:], clock[0] = 0, -1, 0
    K.project_band(flat, model.edges, model.rest_lengths, np.ones(model.n_vertices, bool), forward, 0.05, moved,
                   seen, clock)  # fmt: skip
    met = clock[0]
    K.project_band(flat, model.edges, model.rest_lengths, np.ones(model.n_vertices, bool), backward, 0.05, moved,
                   seen, clock)  # fmt: skip
    assert 0 < (seen > met).sum() < model.n_edges / 3


def test_project_tethers_matches_reference_and_moves_only_what_is_out_of_reach(crumpled, rng):
    """Points on random triangles tethered to two random polylines (through `Tethers.project`, so with its
    nearest-segment cache): the kernel moves what the numpy reference
    moves, leaves fixed vertices and points already within reach alone, and puts the rest exactly at reach."""
    model, pos = crumpled
    n = 40
    faces = rng.integers(0, model.n_faces, n)
    bary = rng.dirichlet(np.ones(3), n)
    lines = [pos.mean(axis=0) + rng.normal(0.0, 0.03, (6, 3)), pos.mean(axis=0) + rng.normal(0.0, 0.03, (4, 3))]
    tethers = Tethers.from_polylines(
        [(faces[:25], bary[:25], lines[0]), (faces[25:], bary[25:], lines[1])], model.faces, reach_m=0.02
    )
    movable = rng.random(model.n_vertices) > 0.2
    movable[tethers.tri[-1]] = True
    got = pos.copy()
    worst = tethers.project(got, movable)
    expect, expect_worst = ref.project_tethers(pos, tethers.tri, tethers.bary, movable, lines, tethers.line_of, 0.02)
    np.testing.assert_allclose(got, expect, atol=ATOL)
    assert worst == pytest.approx(expect_worst) and worst > 0
    np.testing.assert_array_equal(got[~movable], pos[~movable])
    untouched = np.setdiff1d(np.arange(model.n_vertices), tethers.tri.reshape(-1))
    np.testing.assert_array_equal(got[untouched], pos[untouched])
    # The sweep's last point (no later one moves its vertices) ends within reach.
    p = tethers.bary[-1] @ got[tethers.tri[-1]]
    a, b = lines[1][:-1], lines[1][1:]
    t = np.clip(np.einsum("ij,ij->i", p - a, b - a) / np.einsum("ij,ij->i", b - a, b - a), 0, 1)
    assert np.linalg.norm(p - (a + t[:, None] * (b - a)), axis=1).min() <= 0.02 + 1e-9


def test_project_tethers_cache_gives_the_full_search_result(crumpled, rng):
    """The nearest-segment cache only skips searches: over sweeps with small moves (where it is used) and jumps
    (where it must search again), every sweep equals the numpy reference's full search; a one-point polyline is
    a point."""
    model, pos = crumpled
    n = 30
    faces = rng.integers(0, model.n_faces, n)
    bary = rng.dirichlet(np.ones(3), n)
    centre = pos.mean(axis=0)
    lines = [centre + rng.normal(0.0, 0.04, (12, 3)), centre + rng.normal(0.0, 0.01, (1, 3))]
    tethers = Tethers.from_polylines(
        [(faces[:20], bary[:20], lines[0]), (faces[20:], bary[20:], lines[1])], model.faces, reach_m=0.01
    )
    movable = np.ones(model.n_vertices, dtype=bool)
    got = pos.copy()
    used = 0
    for sweep in range(12):
        step = 0.05 if sweep % 4 == 3 else 5e-4  # every fourth sweep a jump past other segments
        got += rng.normal(0.0, step, got.shape)
        before = tethers._seg.copy(), tethers._snap.copy()
        expect, expect_worst = ref.project_tethers(
            got, tethers.tri, tethers.bary, movable, lines, tethers.line_of, 0.01
        )
        worst = tethers.project(got, movable)
        used += int(((tethers._snap == before[1]).all(axis=1) & (before[0] >= 0)).sum())
        np.testing.assert_allclose(got, expect, atol=ATOL)
        assert worst == pytest.approx(expect_worst)
    assert used > 0  # the cache was used in some sweep (else this test shows nothing)
    assert np.isfinite(got).all()
