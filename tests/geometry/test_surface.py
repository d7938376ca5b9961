"""Surface queries: closest points (libigl AABB) and ray hits (embree), checked against exact answers."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from kitsuke.geometry import TriMesh
from kitsuke.geometry.surface import Surface, SurfacePoints, barycentric_coordinates


@pytest.fixture(scope="module")
def sphere() -> Surface:
    m = trimesh.creation.icosphere(subdivisions=3, radius=1.0)
    return Surface(TriMesh(m.vertices, m.faces))


@pytest.fixture(scope="module")
def box() -> Surface:
    m = trimesh.creation.box(extents=[1.0, 1.0, 1.0])
    return Surface(TriMesh(m.vertices, m.faces))


def dense_samples(surface: Surface, n: int, rng) -> np.ndarray:
    """Random points spread over every face (a reference independent of the AABB)."""
    f = rng.integers(0, len(surface.faces), size=n)
    b = rng.dirichlet([1, 1, 1], size=n)
    return surface.evaluate(f, b)


def test_closest_points_against_dense_sampling(sphere):
    rng = np.random.default_rng(1)
    dirs = rng.normal(size=(60, 3))
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    q = dirs * np.repeat([0.5, 1.2, 100.0], 20)[:, None]  # inside, near, and far away
    sp = sphere.closest(q)
    samples = np.vstack([dense_samples(sphere, 100_000, rng), sphere.vertices])
    d_ref = np.array([np.linalg.norm(samples - p, axis=1).min() for p in q])
    assert np.all(sp.distance <= d_ref + 1e-12)  # nothing on the surface is nearer than the answer
    assert np.all(sp.distance >= d_ref - 0.02)  # and the samples come close to it
    np.testing.assert_allclose(np.linalg.norm(q - sp.points, axis=1), sp.distance, atol=1e-12)
    np.testing.assert_allclose(sphere.evaluate(sp.faces, sp.barycentric), sp.points, atol=1e-12)
    assert np.all(sp.barycentric >= 0) and np.allclose(sp.barycentric.sum(axis=1), 1)
    assert sp.hit.all()


def test_closest_on_a_face_is_the_orthogonal_projection(box):
    sp = box.closest([[0.1, -0.2, 0.9], [0.6, 0.0, 0.0]])
    np.testing.assert_allclose(sp.points, [[0.1, -0.2, 0.5], [0.5, 0.0, 0.0]], atol=1e-12)
    np.testing.assert_allclose(sp.distance, [0.4, 0.1], atol=1e-12)
    np.testing.assert_allclose(box.normals_at(sp.faces), [[0, 0, 1], [1, 0, 0]], atol=1e-12)


def test_rays_first_last_and_all_hits(box):
    o = np.array([[0.1, 0.2, 5.0], [0.1, 0.2, 5.0], [3.0, 3.0, 3.0], [0.0, 0.1, 0.0]])
    d = np.array([[0, 0, -1.0], [0, 0, -3.0], [0, 0, -1.0], [1.0, 0, 0]])  # any length; the 3rd misses
    first, last = box.cast(o, d, hit="first"), box.cast(o, d, hit="last")
    np.testing.assert_allclose(first.points[[0, 1]], [[0.1, 0.2, 0.5]] * 2, atol=1e-6)
    np.testing.assert_allclose(last.points[[0, 1]], [[0.1, 0.2, -0.5]] * 2, atol=1e-6)
    np.testing.assert_allclose(first.distance[[0, 1]], 4.5, atol=1e-6)  # along the unit direction
    np.testing.assert_allclose(last.distance[[0, 1]], 5.5, atol=1e-6)
    # A ray that misses: no face, NaN point.
    assert first.faces[2] == -1 and np.isnan(first.points[2]).all() and not first.hit[2]
    # From inside the box, the only hit is the way out.
    np.testing.assert_allclose(first.points[3], [0.5, 0.1, 0.0], atol=1e-6)
    np.testing.assert_allclose(last.points[3], [0.5, 0.1, 0.0], atol=1e-6)
    ray, hits = box.ray_hits(o, d)
    assert np.bincount(ray, minlength=4).tolist() == [2, 2, 0, 1]
    # Hits lie exactly on their rays and on their faces.
    u = d[ray] / np.linalg.norm(d[ray], axis=1, keepdims=True)
    np.testing.assert_allclose(hits.points, o[ray] + hits.distance[:, None] * u, atol=1e-12)
    np.testing.assert_allclose(box.evaluate(hits.faces, hits.barycentric), hits.points, atol=1e-6)


def test_bad_queries_raise(box):
    with pytest.raises(ValueError, match="zero"):
        box.cast([[0, 0, 2]], [[0, 0, 0]])
    with pytest.raises(ValueError, match="NaN"):
        box.closest([[np.nan, 0, 0]])
    with pytest.raises(ValueError, match="origins"):
        box.ray_hits([[0, 0, 2]], [[0, 0, 1], [0, 0, 1]])
    with pytest.raises(ValueError, match="hit must be"):
        box.cast([[0, 0, 2]], [[0, 0, -1]], hit="middle")
    assert len(box.closest(np.zeros((0, 3)))) == 0


def test_barycentric_coordinates_recover_known_weights():
    rng = np.random.default_rng(2)
    tri = rng.normal(size=(100, 3, 3))
    w = rng.dirichlet([1, 1, 1], size=100)
    p = np.einsum("ij,ijk->ik", w, tri)
    np.testing.assert_allclose(barycentric_coordinates(tri, p), w, atol=1e-9)
    # Off the plane: the projection's coordinates.
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    np.testing.assert_allclose(barycentric_coordinates(tri, p + 0.3 * n), w, atol=1e-9)
    degenerate = np.zeros((1, 3, 3))
    np.testing.assert_allclose(barycentric_coordinates(degenerate, np.ones((1, 3))), [[1, 0, 0]])


def test_surface_points_take_and_of(box):
    sp = box.closest([[0, 0, 1.0], [0, 0, -1.0], [1.0, 0, 0]])
    sub = sp.take(np.array([2, 0]))
    assert isinstance(sub, SurfacePoints) and len(sub) == 2
    np.testing.assert_allclose(sub.points, sp.points[[2, 0]])
    assert Surface.of(box) is box and Surface.of(box.mesh) is not box
