"""Arc-length helpers for the wrap: parameters, resampling in the plane, in space and on the body surface."""

from __future__ import annotations

import numpy as np
import pytest

from kitsuke.dressing import (
    BodyStroke,
    PatternStroke,
    StrokePair,
    Strokes,
    arc_length,
    arc_parameters,
    interpolate_polyline,
    resample_on_surface,
    resample_polyline,
    resolve_strokes,
    stroke_coordinates,
    surface_length,
)
from kitsuke.dressing._polyline import polygon_distance, polygon_inside


def test_arc_length_and_parameters():
    p = np.array([[0.0, 0.0], [3.0, 4.0], [3.0, 10.0]])
    np.testing.assert_allclose(arc_length(p), [0, 5, 11])
    np.testing.assert_allclose(arc_parameters(p), [0, 5 / 11, 1])
    with pytest.raises(ValueError):
        arc_parameters(np.zeros((3, 2)))


@pytest.mark.parametrize("dim", [2, 3])
def test_resample_is_equally_spaced_and_on_the_polyline(dim):
    rng = np.random.default_rng(dim)
    p = np.cumsum(rng.normal(size=(7, dim)), axis=0)
    r = resample_polyline(p, 50)
    assert r.shape == (50, dim)
    np.testing.assert_array_equal(r[0], p[0])
    np.testing.assert_array_equal(r[-1], p[-1])
    # Equal steps along the curve: each sample's arc length is k / 49 of the total.
    total = arc_length(p)[-1]
    r2 = interpolate_polyline(p, np.linspace(0, total, 50))
    np.testing.assert_allclose(r, r2, atol=1e-12)
    # On the polyline: resampling at the original knots' arc lengths returns the knots.
    np.testing.assert_allclose(interpolate_polyline(p, arc_length(p)), p, atol=1e-12)


def test_resample_skips_repeated_points():
    p = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [2.0, 0.0]])
    np.testing.assert_allclose(resample_polyline(p, 5)[:, 0], [0, 0.5, 1, 1.5, 2])


def test_pattern_stroke_helpers():
    s = PatternStroke("a", [[0, 0], [0, 10], [10, 10]])
    assert s.length_cm == 20
    np.testing.assert_allclose(s.resample(5), [[0, 0], [0, 5], [0, 10], [5, 10], [10, 10]])
    np.testing.assert_allclose(s.arc_parameters(), [0, 0.5, 1])


def test_stroke_coordinates():
    stroke = np.array([[0.0, 0.0], [10.0, 0.0], [10.0, 10.0]])
    q = np.array([[5.0, 2.0], [5.0, -3.0], [12.0, 5.0], [-2.0, -1.0], [8.0, 5.0]])
    s, off, seg = stroke_coordinates(q, stroke)
    np.testing.assert_allclose(s, [5, 5, 15, 0, 15])
    # Left of the direction is positive; beyond the start, the distance to it, signed by the first segment's
    # side.
    np.testing.assert_allclose(off, [2, -3, -2, -np.sqrt(5), 2])
    np.testing.assert_array_equal(seg, [0, 0, 1, 0, 1])


def test_polygon_inside_and_distance():
    square = np.array([[0.0, 0.0], [4.0, 0.0], [4.0, 4.0], [0.0, 4.0]])
    q = np.array([[1.0, 1.0], [5.0, 1.0], [2.0, 4.5], [3.9, 2.0]])
    np.testing.assert_array_equal(polygon_inside(q, square), [True, False, False, True])
    np.testing.assert_allclose(polygon_distance(q, square), [1, 1, 0.5, 0.1])


def test_surface_resampling_follows_the_body(body_surface, kimono):
    # A stroke of 3 points over the shoulder, front to back: its chords cut through the body; resampling on
    # the
    # surface follows the skin, so it is longer than the chords and every sample is on the surface.
    pts = np.array([[0.12, 1.30, 0.10], [0.12, 1.40, 0.01], [0.12, 1.30, -0.06]])
    st = (
        resolve_strokes(
            Strokes([StrokePair(1, PatternStroke("migoro_left", [[5, 120], [5, 140]]), BodyStroke(points=pts))]),
            kimono,
            body_surface,
        )
        .pair(1)
        .body
    )
    r = st.resample(body_surface, 40)
    assert len(r) == 40 and body_surface.closest(r.points).distance.max() < 1e-9
    steps = np.linalg.norm(np.diff(r.points, axis=0), axis=1)
    assert steps.max() / steps.min() < 1.3  # about equal steps along the surface path
    chord = arc_length(st.surface_points)[-1]
    along = surface_length(body_surface, st.surface_points)
    assert along > chord * 1.02 and abs(steps.sum() - along) < 0.01 * along
    direct = resample_on_surface(body_surface, st.surface_points, 40)
    np.testing.assert_allclose(direct.points, r.points)
