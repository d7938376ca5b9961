"""ClothModel topology and rest shape; ClothState; parameter validation."""

from __future__ import annotations

import numpy as np
import pytest

from kitsuke.cloth import ClothModel, ClothParams, ClothState, grid_sheet, grid_tube, locality_order
from kitsuke.errors import InputError
from kitsuke.metrics import mesh_edges


def test_sheet_topology():
    uv, f = grid_sheet(5, 4, 0.01)
    m = ClothModel.from_flat(f, uv)
    assert (m.n_vertices, m.n_faces) == (20, 24)
    # Euler: V - E + F = 1 for a disc.
    assert m.n_vertices - m.n_edges + m.n_faces == 1
    np.testing.assert_array_equal(m.edges, mesh_edges(f))
    np.testing.assert_allclose(m.rest_lengths, np.linalg.norm(uv[m.edges[:, 0]] - uv[m.edges[:, 1]], axis=1))
    np.testing.assert_allclose(m.rest_areas.sum(), 4 * 3 * 1e-4)
    assert len(m.hinges) == (m.edge_faces[:, 1] >= 0).sum()
    assert not m.seam_edges.any()
    assert m.boundary_vertices.sum() == 2 * (5 + 4) - 4
    # Hinges: a, b are the edge; c and d are the opposite corners of the two faces.
    for (a, b, c, d), (f1, f2) in zip(m.hinges, m.hinge_faces):
        assert {a, b, c} == set(f[f1]) and {a, b, d} == set(f[f2])
    # CSR: each vertex's corners are its own; adjacency lists each edge both ways.
    for v in range(m.n_vertices):
        corners = m.vertex_corners[m.vertex_corners_ptr[v] : m.vertex_corners_ptr[v + 1]]
        assert (f.reshape(-1)[corners] == v).all()
        nb = m.adjacency[m.adjacency_ptr[v] : m.adjacency_ptr[v + 1]]
        eidx = m.adjacency_edge[m.adjacency_ptr[v] : m.adjacency_ptr[v + 1]]
        assert (np.sort(m.edges[eidx], axis=1) == np.sort(np.c_[np.full(len(nb), v), nb], axis=1)).all()
        assert (np.diff(nb) > 0).all()
    assert len(m.adjacency) == 2 * m.n_edges
    # Face adjacency agrees with edge_faces, and the sheet is consistently wound.
    for f1, f2 in m.edge_faces:
        if f2 >= 0:
            assert f2 in m.face_adjacency[f1] and f1 in m.face_adjacency[f2]
    assert (m.face_adjacency_sign == 1).all()


def test_tube_seam_is_detected_and_rest_lengths_kept():
    faces, rc, uv = grid_tube(6, 4, 0.01)
    m = ClothModel.from_corners(faces, rc)
    assert m.n_vertices == 24
    assert m.n_vertices - m.n_edges + m.n_faces == 0  # an annulus
    seam = m.edges[m.seam_edges]
    assert len(seam) == 3  # the vertical edges of column 0, where the sheet's two sides meet
    assert (seam % 6 == 0).all()
    np.testing.assert_allclose(m.rest_lengths[m.seam_edges], 0.01)
    np.testing.assert_allclose(m.rest_areas.sum(), 6 * 3 * 1e-4)


def test_clockwise_rest_triangles_are_reflected():
    uv, f = grid_sheet(3, 3, 0.01)
    a = ClothModel.from_flat(f, uv)
    b = ClothModel.from_flat(f, uv * [-1.0, 1.0])  # a mirrored pattern: every rest triangle clockwise
    np.testing.assert_allclose(b.rest_lengths, a.rest_lengths)
    np.testing.assert_allclose(b.rest_areas, a.rest_areas)
    e1 = b.rest_corners[:, 1] - b.rest_corners[:, 0]
    e2 = b.rest_corners[:, 2] - b.rest_corners[:, 0]
    assert (e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0] > 0).all()


@pytest.mark.parametrize(
    "faces, corners, message",
    [
        (np.array([[0, 1, 2]]), np.zeros((1, 3, 2)), "degenerate"),
        (np.array([[0, 1, 1]]), np.ones((1, 3, 2)), "repeats"),
        (np.array([[0, 1, 2]]), np.zeros((2, 3, 2)), "shape"),
        (np.array([[0.0, 1, 2]]), np.zeros((1, 3, 2)), "integer"),
        (np.array([[0, 1, 2], [0, 1, 3], [0, 1, 4]]), np.tile([[0, 0], [1, 0], [0, 1]], (3, 1, 1)), "more than two"),
        (np.array([[0, 1, 2]]), np.full((1, 3, 2), np.nan), "NaN"),
    ],
)
def test_bad_model_input(faces, corners, message):
    with pytest.raises(InputError, match=message):
        ClothModel.from_corners(faces, corners)


def test_params_validated():
    with pytest.raises(InputError, match="friction"):
        ClothParams(friction=-0.5)
    with pytest.raises(InputError, match="gravity_step_m"):
        ClothParams(gravity_step_m=-1)
    with pytest.raises(InputError, match="contact_distance_m"):
        ClothParams(contact_offset_m=0.01, contact_distance_m=0.005)


def test_state_validated():
    uv, f = grid_sheet(3, 3, 0.01)
    m = ClothModel.from_flat(f, uv)
    with pytest.raises(InputError, match="positions"):
        ClothState.new(m, np.zeros((8, 3)))
    with pytest.raises(InputError, match="NaN"):
        ClothState.new(m, np.full((9, 3), np.nan))
    with pytest.raises(InputError, match="pinned"):
        ClothState.new(m, np.zeros((9, 3)), pinned=np.zeros(3, dtype=bool))
    s = ClothState.new(m, np.zeros((9, 3)))
    assert s.face_active.all() and not s.pinned.any() and (s.contacts.face == -1).all()
    c = s.copy()
    c.positions[0, 0] = 1.0
    assert s.positions[0, 0] == 0.0


def test_locality_order_is_a_permutation_that_narrows_the_band(rng):
    uv, f = grid_sheet(12, 12, 0.01)
    perm = rng.permutation(len(uv))
    shuffled = np.argsort(perm)[f]  # vertex k of the shuffled mesh is old vertex perm[k]
    vorder, forder = locality_order(shuffled, len(uv))
    np.testing.assert_array_equal(np.sort(vorder), np.arange(len(uv)))
    np.testing.assert_array_equal(np.sort(forder), np.arange(len(f)))
    rank = np.argsort(vorder)
    reordered = rank[shuffled[forder]]

    def bandwidth(faces):
        return int((faces.max(axis=1) - faces.min(axis=1)).max())

    assert bandwidth(reordered) < bandwidth(shuffled) / 3
    # Same triangles, same rest shape.
    a = ClothModel.from_flat(shuffled, uv[perm])
    b = ClothModel.from_corners(reordered, a.rest_corners[forder])
    np.testing.assert_allclose(np.sort(b.rest_lengths), np.sort(a.rest_lengths))


def test_with_params_shares_the_topology_and_leaves_the_original_alone():
    uv, f = grid_sheet(5, 4, 0.02)
    m = ClothModel.from_flat(f, uv)
    soft = m.with_params(ClothParams(friction=0.1, gravity_step_m=0.0))
    assert soft.params.friction == 0.1 and m.params.friction == ClothParams().friction
    assert soft.edges is m.edges and soft.rest_lengths is m.rest_lengths and soft.hinges is m.hinges
    with pytest.raises(InputError, match="ClothParams"):
        m.with_params({"friction": 0.1})
