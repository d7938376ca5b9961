"""Edge geometry: GarmentCode's relative control points, curves, arcs, areas, intersections, rotations, folds."""

from __future__ import annotations

import math

import numpy as np
import pytest

from kitsuke.pattern import Curve, Fold, Piece, Placement
from kitsuke.pattern import _geometry as geo


def test_relative_points_follow_garmentcode():
    # x along the edge, y across it as a fraction of its length, positive to the LEFT of the direction.
    p0, p1 = np.array([1.0, 1.0]), np.array([5.0, 1.0])
    got = geo.rel_to_abs(p0, p1, np.array([[0.25, 0.5], [1.0, -0.25]]))
    np.testing.assert_allclose(got, [[2.0, 3.0], [5.0, 0.0]])
    np.testing.assert_allclose(geo.abs_to_rel(p0, p1, got), [[0.25, 0.5], [1.0, -0.25]])


def test_quadratic_and_cubic_points():
    p0, p1 = np.array([0.0, 0.0]), np.array([10.0, 0.0])
    # Quadratic with control (5, 4): B(1/2) = (5, 2).
    mid = geo.curve_points(p0, p1, "quadratic", np.array([[0.5, 0.4]]), np.array([0.0, 0.5, 1.0]))
    np.testing.assert_allclose(mid, [[0, 0], [5, 2], [10, 0]], atol=1e-12)
    # Cubic with controls (0, 3) and (10, 3): B(1/2) = (5, 2.25).
    c = geo.curve_points(p0, p1, "cubic", np.array([[0.0, 0.3], [1.0, 0.3]]), np.array([0.5]))
    np.testing.assert_allclose(c, [[5.0, 2.25]], atol=1e-12)


def test_circle_arc_exact():
    # Half circle of radius 5 over a 10 cm chord, bulging to the left (y = +0.5): length 5 pi.
    p = Piece("p", [[0, 0], [10, 0], [10, -10], [0, -10]][::-1], {})
    edge = Piece("arc", [[0, 0], [10, 0], [5, -8]], {0: Curve("circle", [[0.5, 0.5]])})
    assert math.isclose(edge.edge_length(0), 5 * math.pi, rel_tol=1e-6)
    pts = edge.sample_edge(0)
    np.testing.assert_allclose(np.linalg.norm(pts - [5, 0], axis=1), 5.0, atol=1e-9)
    np.testing.assert_allclose(edge.edge_points(0, [0.5]), [[5.0, 5.0]], atol=1e-12)  # through (0.5, 0.5)
    assert p.area == pytest.approx(100.0)


def test_curve_sampling_tolerance_and_reversal():
    piece = Piece("p", [[0, 0], [20, 0], [20, 20], [0, 20]], {0: Curve("cubic", [[0.2, -0.3], [0.7, 0.25]])})
    dense = piece.edge_points(0, np.linspace(0, 1, 20001))
    coarse = piece.sample_edge(0, tol_cm=0.01)
    # Every dense point lies within the tolerance of the coarse polyline.
    a, b = coarse[:-1], coarse[1:]
    ab = b - a
    t = np.clip(((dense[:, None] - a) * ab).sum(-1) / (ab * ab).sum(-1), 0, 1)
    d = np.linalg.norm(dense[:, None] - (a + t[..., None] * ab), axis=-1).min(axis=1)
    assert d.max() <= 0.01
    # The reversed curve on the reversed edge is the same set of points.
    rev = Piece("r", [[20, 0], [0, 0], [0, 20]], {0: piece.curves[0].reversed()})
    np.testing.assert_allclose(rev.edge_points(0, np.linspace(0, 1, 11)), dense[::2000][::-1], atol=1e-9)


def test_area_of_curved_piece_matches_analytic():
    # Square with its bottom edge bulging outwards (y = -0.3: right of a CCW edge): the parabola peaks at half the
    # control's 3 cm and adds 2/3 * 10 * 1.5 = 10 cm^2.
    piece = Piece("p", [[0, 0], [10, 0], [10, 10], [0, 10]], {0: Curve("quadratic", [[0.5, -0.3]])})
    assert piece.area == pytest.approx(110.0, rel=1e-12)


def test_self_intersections():
    square = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=float)
    assert geo.self_intersections(square) is None
    bowtie = np.array([[0, 0], [1, 1], [1, 0], [0, 1]], dtype=float)
    assert geo.self_intersections(bowtie) is not None
    touching = np.array([[0, 0], [2, 0], [2, 2], [1, 0], [0, 2]], dtype=float)  # a vertex on another edge
    assert geo.self_intersections(touching) is not None


def test_euler_round_trip_and_convention():
    rng = np.random.default_rng(3)
    for angles in rng.uniform(-180, 180, (200, 3)):
        m = geo.euler_xyz_matrix(angles)
        np.testing.assert_allclose(geo.euler_xyz_matrix(geo.matrix_to_euler_xyz(m)), m, atol=1e-9)
    # R = Rz Ry Rx: x first. A 90° turn about x then about z takes +y to +z, then keeps it at +z.
    m = geo.euler_xyz_matrix([90, 0, 90])
    np.testing.assert_allclose(m @ [0, 1, 0], [0, 0, 1], atol=1e-12)
    np.testing.assert_allclose(geo.matrix_to_euler_xyz(geo.euler_xyz_matrix([0, 180, 0])), [0, 180, 0])


def test_fold_is_isometric_and_puts_the_back_behind():
    fold = Fold(y_cm=50.0, diameter_cm=20.0)
    y = np.linspace(0, 100, 2001)
    pts = fold.bend(np.c_[np.zeros_like(y), y])
    steps = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    assert steps.sum() == pytest.approx(100.0, rel=1e-4)  # no stretch
    assert pts[0, 2] == 0 and pts[-1, 2] == pytest.approx(-20.0)
    top = pts[:, 1].max()
    assert top == pytest.approx(50.0 - (math.pi / 2 - 1) * 10.0)  # the fold line is the top of the bend
    placed = Placement([0, 1, 0], [0, 0, 0], fold).apply(np.array([[0.0, 50.0]]))
    np.testing.assert_allclose(placed, [[0.0, 1 + top / 100, -0.1]], atol=1e-12)
