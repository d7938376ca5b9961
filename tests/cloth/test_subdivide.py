"""Adaptive sqrt(3) subdivision: manifold kept, boundary and seams kept, rest area kept, refined only where asked
(or where the paper's edge test fires)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from kitsuke.cloth import ClothModel, ClothState, colliding_edges, grid_sheet, grid_tube, refine, sqrt3_split, track
from kitsuke.errors import InputError
from kitsuke.metrics import mesh_edges

from .conftest import flat_sheet


def check_manifold(faces: np.ndarray) -> None:
    """Every directed edge once (consistent winding, at most two faces per edge), no repeated vertex in a face."""
    assert not ((faces[:, 0] == faces[:, 1]) | (faces[:, 1] == faces[:, 2]) | (faces[:, 2] == faces[:, 0])).any()
    directed = faces[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2)
    assert len(np.unique(directed, axis=0)) == len(directed)


def boundary_edges(faces: np.ndarray) -> set[tuple[int, int]]:
    e = np.sort(faces[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1)
    u, c = np.unique(e, axis=0, return_counts=True)
    return {tuple(x) for x in u[c == 1]}


def signed_areas(c: np.ndarray) -> np.ndarray:
    e1, e2 = c[:, 1] - c[:, 0], c[:, 2] - c[:, 0]
    return 0.5 * (e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])


def test_uniform_step_on_a_sheet():
    uv, f = grid_sheet(7, 6, 0.01)
    rc = uv[f]
    pos = np.c_[uv, np.zeros(len(uv))]
    r = sqrt3_split(
        f,
        rc,
        np.ones(len(f), dtype=bool),
        vertex_data={"positions": pos},
        face_data={"piece": np.arange(len(f)) % 2},
        corner_data={"uv": rc},
    )
    assert r.n_vertices == len(uv) + len(f) and len(r.faces) == 3 * len(f)
    check_manifold(r.faces)
    assert boundary_edges(r.faces) == boundary_edges(f)
    interior = len(mesh_edges(f)) - len(boundary_edges(f))
    assert r.flipped == interior  # every interior edge of a uniform step flips
    assert not r.pending[np.isin(r.faces, np.unique(f)).sum(axis=1) < 2].any()
    np.testing.assert_allclose(signed_areas(r.rest_corners).sum(), signed_areas(rc).sum(), rtol=1e-12)
    assert (signed_areas(r.rest_corners) > 0).all()
    # New vertices sit at their triangle's centroid, in 3D and in the pattern; attributes follow.
    np.testing.assert_allclose(r.vertex_data["positions"][len(uv) :], pos[f].mean(axis=1))
    np.testing.assert_allclose(r.corner_data["uv"], r.rest_corners)
    np.testing.assert_array_equal(r.face_data["piece"], (np.arange(len(f)) % 2)[r.parent_face])
    # The corners' pattern positions agree with the vertices' (one chart): uv[v] for old, centroid for new.
    full_uv = np.r_[uv, uv[f].mean(axis=1)]
    np.testing.assert_allclose(r.rest_corners, full_uv[r.faces], atol=1e-15)
    # sqrt(3): the new edges are 1/sqrt(3) of the old ones on a regular patch (here a right-triangle grid).
    assert np.median(np.linalg.norm(np.diff(full_uv[mesh_edges(r.faces)], axis=1)[:, 0], axis=1)) < 0.0085


def test_adaptive_step_changes_only_the_selection_and_graded_neighbours():
    uv, f = grid_sheet(9, 9, 0.01)
    rc = uv[f]
    sel = np.zeros(len(f), dtype=bool)
    centre = np.argmin(np.linalg.norm(uv[f].mean(axis=1) - 0.04, axis=1))
    sel[centre] = True
    r1 = sqrt3_split(f, rc, sel)
    assert r1.split.sum() == 1 and r1.flipped == 0  # neighbours are level 0 = not lower: no growth, no flip
    check_manifold(r1.faces)
    assert r1.pending.sum() == 3
    untouched = np.flatnonzero(~r1.split)
    np.testing.assert_array_equal(r1.faces[: len(untouched)], f[untouched])
    # Second step on one child: its level-0 neighbours must be split first (neighbour rule); the pending edge
    # between the first child and its neighbour flips once both sides are split at the same level.
    child = len(untouched)  # first child of the split face
    sel2 = np.zeros(len(r1.faces), dtype=bool)
    sel2[child] = True
    r2 = sqrt3_split(r1.faces, r1.rest_corners, sel2, level=r1.level, pending=r1.pending)
    check_manifold(r2.faces)
    assert r2.split.sum() > 1
    grown = np.flatnonzero(r2.split)
    assert set(r1.level[grown]) <= {0, 1}
    assert boundary_edges(r2.faces) == boundary_edges(f)
    np.testing.assert_allclose(signed_areas(r2.rest_corners).sum(), signed_areas(rc).sum(), rtol=1e-12)
    assert (signed_areas(r2.rest_corners) > 0).all()
    assert r2.flipped >= 1
    # Levels across any edge differ by at most one.
    e = np.sort(r2.faces[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1)
    owner = np.repeat(np.arange(len(r2.faces)), 3)
    order = np.lexsort((e[:, 1], e[:, 0]))
    same = np.flatnonzero((np.diff(e[order], axis=0) == 0).all(axis=1))
    assert np.abs(r2.level[owner[order[same]]] - r2.level[owner[order[same + 1]]]).max() <= 1


def test_seam_edges_and_boundary_are_kept():
    faces, rc, _ = grid_tube(8, 5, 0.01)
    model = ClothModel.from_corners(faces, rc)
    seam = {tuple(e) for e in model.edges[model.seam_edges]}
    r = sqrt3_split(model.faces, model.rest_corners, np.ones(model.n_faces, dtype=bool))
    check_manifold(r.faces)
    assert seam <= {tuple(e) for e in mesh_edges(r.faces)}  # no seam edge flipped away
    assert boundary_edges(r.faces) == boundary_edges(faces)
    refined = ClothModel.from_corners(r.faces, r.rest_corners)
    assert refined.seam_edges.sum() == len(seam)
    np.testing.assert_allclose(refined.rest_areas.sum(), model.rest_areas.sum(), rtol=1e-12)


def paper_edge_test(p, edges, dist, normal):
    """The paper's test, edge by edge, written out with math."""
    out = []
    for a, b in edges:
        hit = False
        for i, j in ((a, b), (b, a)):
            ab = p[j] - p[i]
            L = math.sqrt(ab @ ab)
            s = -(ab @ normal[i]) / L
            d = max(dist[i], 0.0)
            q = math.asin(max(-1.0, min(1.0, s)))
            hit |= s > 0 and (d + L) * math.sin(q) < L and (d + L) * math.cos(q) < L
        out.append(hit)
    return np.array(out)


def test_colliding_edges_and_refine_where_they_fire(sphere_collider):
    """A coarse sheet (4 cm edges) whose middle is laid onto the 10 cm sphere 0.5 mm above it (its edges are
    chords dipping into the surface) and whose rim stands 5 cm off: the test fires on the middle only."""
    model, pos = flat_sheet(9, 9, 0.04)
    xz = pos[:, :2] - pos[:, :2].mean(axis=0)
    on = np.linalg.norm(xz, axis=1) < 0.09
    direction = np.c_[xz[:, 0], np.full(len(xz), 0.1), xz[:, 1]]
    direction /= np.linalg.norm(direction, axis=1, keepdims=True)
    pos = direction * np.where(on, 0.1005, 0.15)[:, None]
    state = ClothState.new(model, pos)
    track(model, state, sphere_collider)
    fires = colliding_edges(model, state)
    c = state.contacts
    np.testing.assert_array_equal(fires, paper_edge_test(pos, model.edges, c.distance, c.normal))
    assert fires.sum() > 10
    assert on[model.edges[fires]].any(axis=1).all()  # every firing edge has an end lying on the sphere
    new_model, new_state, r = refine(model, state, sphere_collider)
    chosen = np.zeros(model.n_faces, dtype=bool)
    ef = model.edge_faces[fires].reshape(-1)
    chosen[ef[ef >= 0]] = True
    np.testing.assert_array_equal(r.split, chosen)  # all level 0: the neighbour rule adds nothing
    assert new_model.n_vertices == model.n_vertices + chosen.sum()
    np.testing.assert_array_equal(new_state.positions[: model.n_vertices], pos)
    np.testing.assert_allclose(new_model.rest_areas.sum(), model.rest_areas.sum(), rtol=1e-12)
    # Far from the contact nothing changed: the faces away from firing edges are the same triangles.
    kept = {tuple(t) for t in model.faces[~chosen]}
    assert kept <= {tuple(t) for t in new_model.faces}
    # The next refinement stops at max_level.
    _, _, r2 = refine(new_model, new_state, sphere_collider, level=r.level, pending=r.pending, max_level=1)
    assert not (r2.split & (r.level >= 1)).any()


def test_sqrt3_rejects_bad_input():
    uv, f = grid_sheet(3, 3, 0.01)
    with pytest.raises(InputError, match="select"):
        sqrt3_split(f, uv[f], np.ones(3, dtype=bool))
    with pytest.raises(InputError, match="positions"):
        sqrt3_split(f, uv[f], np.ones(len(f), dtype=bool), vertex_data={"positions": np.zeros((2, 3))})


def test_one_face_with_corner_data_splits_without_flips():
    """A single selected face has no partner at its level: it is split 1-to-3 and nothing flips, and its corner
    data is carried all the same (an empty list of flip candidates once failed to reshape)."""
    uv, f = grid_sheet(4, 4, 0.02)
    select = np.zeros(len(f), dtype=bool)
    select[7] = True
    r = sqrt3_split(f, uv[f], select, corner_data={"uv": uv[f] * 2.0})
    assert r.flipped == 0 and len(r.faces) == len(f) + 2
    np.testing.assert_allclose(r.corner_data["uv"], r.rest_corners * 2.0)


def test_tethers_follow_a_refinement_to_the_faces_holding_their_points():
    """Tethers on a sheet bent in z, refined twice round its middle (with edge flips): every point keeps its place
    in the rest shape, now on a face of the refined cloth, and so its x and y on the cloth (linear over the rest
    plane, whatever the triangles); z moves by what the flips change of the bent surface (under 0.1 mm here); a
    tether on a face the cloth does not have is refused."""
    from kitsuke.cloth import Tethers

    model, rest = flat_sheet(7, 6, 0.02)
    x = rest.copy()
    x[:, 2] = 0.3 * (x[:, 0] - 0.06) ** 2  # bent: a point between old corners lies off a refined surface later
    rng = np.random.default_rng(7)
    faces = rng.choice(model.n_faces, 40)
    bary = rng.dirichlet(np.ones(3), 40)
    line = np.array([[0.0, 0.05, 0.0], [0.12, 0.05, 0.0]])
    tethers = Tethers.from_polylines([(faces, bary, line)], model.faces, 0.01)
    m, s = model, ClothState.new(model, x)
    level = pending = None
    for _ in range(2):
        select = np.abs(m.rest_corners[..., 0].mean(axis=1) - 0.06) < 0.03
        before = m
        m, s, r = refine(m, s, select=select, level=level, pending=pending)
        level, pending = r.level, r.pending
        assert r.flipped > 0
        tethers = tethers.refined(before, m, r.parent_face)
    key = {tuple(sorted(f)): i for i, f in enumerate(m.faces)}
    face = np.array([key[tuple(sorted(t))] for t in tethers.tri])  # every tether on a face of the refined cloth
    rest_point = np.einsum("nk,nkc->nc", tethers.bary, m.rest_corners[face])
    was = np.einsum("nk,nkc->nc", bary, model.rest_corners[faces])
    np.testing.assert_allclose(rest_point, was, atol=1e-12)
    now = np.einsum("nk,nkc->nc", tethers.bary, s.positions[tethers.tri])
    np.testing.assert_allclose(now[:, :2], was, atol=1e-12)
    assert np.abs(now[:, 2] - 0.3 * (was[:, 0] - 0.06) ** 2).max() < 1e-4
    assert (tethers.bary >= 0).all() and np.allclose(tethers.bary.sum(axis=1), 1.0)
    wrong = Tethers.from_polylines([(faces[:1], bary[:1], line)], model.faces[:, [0, 2, 1]] + 1, 0.01)
    with pytest.raises(InputError, match="triangle the cloth does not have"):
        wrong.refined(model, m, r.parent_face)


def test_refined_tethers_stay_in_their_piece_across_a_seam():
    """Two pieces sewn along one edge, each cut in its own pattern frame, the second's frame shifted so that its
    faces beside the seam cover the same rest square as the first's: a point of the first piece next to the seam
    also lies "inside" faces of the second in rest coordinates. Refined round the seam, every tether stays on a
    face of its own piece, at its own rest point."""
    from kitsuke.cloth import ClothParams, Tethers, grid_sheet

    uv, f = grid_sheet(5, 5, 0.02)
    n = len(uv)
    # The second piece's column i = 0 is the first piece's column i = 4 (the seam), shared vertices.
    second = np.arange(n) + n
    second[uv[:, 0] == 0] = np.flatnonzero(uv[:, 0] == 0.08)
    faces = np.concatenate([f, second[f]])
    corners = np.concatenate([uv[f], uv[f] + [0.06, 0.0]])  # beside the seam, both pieces at rest x 0.06-0.08
    used = np.unique(faces)
    remap = np.full(2 * n, -1)
    remap[used] = np.arange(len(used))
    faces = remap[faces]
    model = ClothModel.from_corners(faces, corners, n_vertices=len(used), params=ClothParams())
    x = np.zeros((len(used), 3))
    x[remap[:n], :2] = uv
    x[remap[second], 0] = 0.08 + uv[:, 0]  # the second piece continues the first in 3D
    x[remap[second], 1] = uv[:, 1]
    near_seam = np.flatnonzero(uv[f].mean(axis=1)[:, 0] > 0.06)  # faces of the first piece beside the seam
    bary = np.full((len(near_seam), 3), 1 / 3)
    tethers = Tethers.from_polylines([(near_seam, bary, np.array([[0.0, 0.0, 0.0], [0.1, 0.0, 0.0]]))], faces, 0.01)
    state = ClothState.new(model, x)
    refined, _, r = refine(model, state, select=np.ones(model.n_faces, dtype=bool))
    moved = tethers.refined(model, refined, r.parent_face)
    key = {tuple(sorted(t)): i for i, t in enumerate(refined.faces)}
    face = np.array([key[tuple(sorted(t))] for t in moved.tri])
    assert (r.parent_face[face] < len(f)).all()  # the first piece's faces
    np.testing.assert_allclose(
        np.einsum("nk,nkc->nc", moved.bary, refined.rest_corners[face]), uv[f[near_seam]].mean(axis=1), atol=1e-12
    )
