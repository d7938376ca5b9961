"""Triangles a pattern stroke crosses, against a brute-force reference; and the segment-triangle kernel's
cases."""

from __future__ import annotations

import numpy as np
import pytest

from kitsuke.dressing import PatternStroke, triangles_crossed
from kitsuke.dressing._crossing import segments_cross_triangles

from .reference import triangles_crossed_reference


def random_strokes(piece, rng, n=6):
    lo, hi = piece.bounds
    out = []
    for _ in range(n):
        k = int(rng.integers(2, 7))
        out.append(lo + (hi - lo) * rng.uniform(0.02, 0.98, size=(k, 2)))
    return out


@pytest.mark.parametrize("piece_name", ["migoro_left", "sode_right", "okumi_left"])
def test_matches_brute_force_on_the_kimono_mesh(kimono_mesh, kimono, piece_name):
    rng = np.random.default_rng(hash(piece_name) % 2**32)
    k = kimono_mesh.piece_names.index(piece_name)
    f0, f1 = kimono_mesh.piece_faces[k]
    tri = kimono_mesh.vertices_cm[kimono_mesh.faces[f0:f1]]
    piece = kimono.piece(piece_name)
    strokes = random_strokes(piece, rng)
    # Also strokes through mesh vertices and along a mesh edge: the touching cases.
    a, b = tri[len(tri) // 2, 0], tri[len(tri) // 2, 1]
    strokes += [
        np.array([a, b]),
        np.array([a, a + [0.7, 0.3]]),
        np.array([a - [1.0, 1.0], a, b + [0.5, 2.0]]),
    ]
    for pts in strokes:
        got = triangles_crossed(kimono_mesh, PatternStroke(piece_name, pts))
        ref = {int(t) + int(f0) for t in triangles_crossed_reference(pts, tri)}
        assert set(got.tolist()) == ref
        assert np.all(np.diff(got) > 0)  # sorted, unique
        assert np.all((got >= f0) & (got < f1))


def test_a_straight_stroke_crosses_a_connected_band(kimono_mesh):
    # A long vertical stroke down the back panel: the crossed triangles form one band about a triangle wide,
    # whose area is roughly length x (1-2 edge lengths).
    got = triangles_crossed(kimono_mesh, PatternStroke("migoro_right", [[15.2, 170.0], [15.2, 250.0]]))
    t = kimono_mesh.vertices_cm[kimono_mesh.faces[got]]
    assert t[:, :, 1].min() <= 170 and t[:, :, 1].max() >= 250
    u, w = t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]
    area = 0.5 * np.abs(u[:, 0] * w[:, 1] - u[:, 1] * w[:, 0]).sum()
    h = kimono_mesh.edge_length_cm
    assert 80 * 0.5 * h < area < 80 * 3 * h


def test_piece_not_in_mesh_gives_nothing(kimono_mesh):
    assert len(triangles_crossed(kimono_mesh, PatternStroke("nope", [[0, 0], [1, 1]]))) == 0


def test_kernel_cases():
    tri = np.array([[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]])
    cases = {
        "inside": ([[0.1, 0.1], [0.2, 0.2]], True),
        "through": ([[-1.0, 0.2], [2.0, 0.2]], True),
        "touch vertex": ([[1.0, 0.0], [2.0, 0.0]], True),
        "along edge": ([[0.2, 0.0], [0.8, 0.0]], True),
        "near miss": ([[0.6, 0.6], [2.0, 2.0]], False),  # starts just beyond the hypotenuse, leaves outwards
        "beside, parallel": ([[-1.0, 1.5], [2.0, 1.5]], False),
        "collinear, beyond": ([[1.5, 0.0], [3.0, 0.0]], False),
        "point inside": ([[0.2, 0.2], [0.2, 0.2]], True),
    }
    for name, (pts, want) in cases.items():
        s, t = segments_cross_triangles(np.array(pts), tri)
        assert (len(s) > 0) == want, name
