"""The drag's building blocks: the surface walk against potpourri3d's geodesic tracer and exact great circles, the
move rule on a sphere, the weights of the dependency graph, the body part's axis."""

from __future__ import annotations

import numpy as np
import pytest

from kitsuke.cloth import BodyCollider, ClothModel, grid_sheet
from kitsuke.dressing import _drag_kernels as K
from kitsuke.dressing._drag_field import body_axis, drag_weights, smooth_falloff
from kitsuke.geometry import TriMesh
from kitsuke.skeleton import INDEX


def _sphere(radius=0.2, subdivisions=5) -> TriMesh:
    import trimesh

    m = trimesh.creation.icosphere(subdivisions=subdivisions, radius=radius)
    return TriMesh(np.asarray(m.vertices, dtype=np.float64), np.asarray(m.faces, dtype=np.int64))


def _random_tangent_moves(col: BodyCollider, n: int, rng, lo=0.01, hi=0.15):
    faces = rng.integers(0, len(col.faces), n)
    bary = rng.dirichlet([2.0, 2.0, 2.0], n)
    vec = rng.normal(size=(n, 3))
    fn = col.face_normals[faces]
    vec -= (vec * fn).sum(1)[:, None] * fn
    vec *= (rng.uniform(lo, hi, n) / np.linalg.norm(vec, axis=1))[:, None]
    return faces, bary, vec


def _trace(col: BodyCollider, faces, bary, vec, max_cross=10_000):
    n = len(faces)
    out = (np.zeros(n, np.int64), np.zeros((n, 3)), np.zeros((n, 3)), np.zeros(n))
    K.trace_points(col.vertices, col.faces, col.face_adjacency, col.face_normals, faces, bary, vec, max_cross, *out)
    return out


@pytest.fixture(scope="module")
def body_collider(body):
    return BodyCollider.from_body(body)


def test_trace_matches_potpourri3d_geodesic_tracer_on_the_body(body_collider):
    """Moving a point along the body surface (up to 15 cm, across many triangles) ends where potpourri3d's
    geodesic tracer (the reference implementation) ends, to 1e-8 m, and travels the whole length."""
    import potpourri3d as pp3d

    col = body_collider
    faces, bary, vec = _random_tangent_moves(col, 60, np.random.default_rng(3))
    _, _, point, dist = _trace(col, faces, bary, vec)
    tracer = pp3d.GeodesicTracer(col.vertices, col.faces)
    ref = [tracer.trace_geodesic_from_face(int(f), b, v)[-1] for f, b, v in zip(faces, bary, vec, strict=True)]
    np.testing.assert_allclose(point, ref, atol=1e-8)
    np.testing.assert_allclose(dist, np.linalg.norm(vec, axis=1), rtol=1e-12)


def test_trace_follows_great_circles_on_a_sphere():
    """On a sphere of radius R the traced point is L / R radians from the start (the polyhedron's geodesic
    differs from the sphere's by its faceting: 0.05 %), and stays on the sphere's surface."""
    r = 0.2
    col = BodyCollider.from_mesh(_sphere(r))
    faces, bary, vec = _random_tangent_moves(col, 100, np.random.default_rng(4), 0.02, 0.5)
    _, _, point, _ = _trace(col, faces, bary, vec)
    start = np.einsum("ij,ijk->ik", bary, col.vertices[col.faces[faces]])
    cos = (start * point).sum(1) / np.linalg.norm(start, axis=1) / np.linalg.norm(point, axis=1)
    angle = np.arccos(np.clip(cos, -1, 1))
    np.testing.assert_allclose(angle * r, np.linalg.norm(vec, axis=1), rtol=5e-4)


def test_trace_drops_the_normal_part_of_the_vector(body_collider):
    """Only the tangential part of a move counts: a vector along the face normal does not move the point, and a
    tilted one moves it by its projection's length."""
    col = body_collider
    faces, bary, vec = _random_tangent_moves(col, 20, np.random.default_rng(5))
    normal = col.face_normals[faces] * 0.05
    f, b, _, dist = _trace(col, faces, bary, normal)
    assert (f == faces).all() and np.allclose(b, bary) and (dist == 0).all()
    _, _, _, dist = _trace(col, faces, bary, vec + normal)
    np.testing.assert_allclose(dist, np.linalg.norm(vec, axis=1), rtol=1e-9)


def _drag_moves(col, pos, weight, follow, vec, face, bary):
    point = np.einsum("ij,ijk->ik", bary, col.vertices[col.faces[face]])
    face, bary, move = face.copy(), bary.copy(), np.zeros_like(pos)
    pos = pos.copy()
    K.drag_moves(
        pos, weight, follow, vec, col.vertices, col.faces, col.face_adjacency, col.face_normals, col.vertex_normals,
        256, face, bary, point, move,
    )  # fmt: skip
    return pos, move


def test_drag_moves_go_straight_where_the_body_falls_away():
    """Outside a sphere the surface curves away from a vertex moved along it: the vertex is translated straight
    (bridging, as cloth does), ending about L^2 / 2(R + h) higher; far from the body (follow 0) it is translated
    too; the weight scales the move (0: no move at all)."""
    r = 0.2
    col = BodyCollider.from_mesh(_sphere(r))
    rng = np.random.default_rng(6)
    faces, bary, vec = _random_tangent_moves(col, 30, rng, 0.02, 0.02)
    foot = np.einsum("ij,ijk->ik", bary, col.vertices[col.faces[faces]])
    pos = foot + 0.008 * foot / np.linalg.norm(foot, axis=1, keepdims=True)
    ones = np.ones(30)
    moved, _ = _drag_moves(col, pos, ones, ones, vec, faces, bary)
    np.testing.assert_allclose(moved, pos + vec, atol=1e-15)
    w = rng.uniform(0, 1, 30)
    w[:5] = 0.0
    scaled, move = _drag_moves(col, pos, w, np.zeros(30), vec, faces, bary)
    np.testing.assert_allclose(scaled, pos + w[:, None] * vec, atol=1e-15)
    assert (move[:5] == 0).all()


def test_drag_moves_keep_cloth_off_a_body_that_comes_towards_it():
    """Inside a sphere whose outside is the sphere's inside (a bowl: the wall rises towards a vertex moved along
    it), a vertex 8 mm off the wall dragged 2 cm along it is lifted back to 8 mm (to the faceting's 0.3 mm),
    where translating it straight would bring it to 7 mm; with follow 0 it is translated straight."""
    r = 0.2
    inner = _sphere(r)
    col = BodyCollider.from_mesh(TriMesh(inner.vertices, inner.faces[:, ::-1]))  # the outside is inside
    faces, bary, vec = _random_tangent_moves(col, 20, np.random.default_rng(8), 0.02, 0.02)
    foot = np.einsum("ij,ijk->ik", bary, col.vertices[col.faces[faces]])
    pos = foot * (1 - 0.008 / r)
    ones = np.ones(20)
    moved, _ = _drag_moves(col, pos, ones, ones, vec, faces, bary)
    np.testing.assert_allclose(r - np.linalg.norm(moved, axis=1), 0.008, atol=3e-4)
    assert (r - np.linalg.norm(pos + vec, axis=1) < 0.0075).all()
    straight, _ = _drag_moves(col, pos, ones, np.zeros(20), vec, faces, bary)
    np.testing.assert_allclose(straight, pos + vec, atol=1e-15)


# -- weights ------------------------------------------------------------------------------------------------------
def _sheet(nx=21, ny=5, spacing=0.01) -> tuple[ClothModel, np.ndarray]:
    uv, faces = grid_sheet(nx, ny, spacing)
    return ClothModel.from_flat(faces, uv), uv


def test_weights_are_one_everywhere_without_pins():
    model, _ = _sheet()
    w, d_grab, d_pin, parent = drag_weights(model, 0, np.zeros(model.n_vertices, bool))
    assert (w == 1).all() and np.isinf(d_pin).all() and d_grab[0] == 0
    assert parent[0] == -1 and (parent[1:] >= 0).all()
    # The parents form a shortest-path tree: each vertex is one edge farther than its parent.
    assert (d_grab[1:] > d_grab[parent[1:]]).all()


def test_weights_fall_smoothly_to_zero_at_a_pin():
    """Along a strip from the grab (x = 0) to a pinned column (x = 20 cm): weight 1 at the grab, 0 at the pins,
    decreasing in between, S(t) of t = d_pin / (d_grab + d_pin): its slope next to the pin is far below the
    linear falloff's (no kink), and the linear option gives t itself."""
    model, uv = _sheet()
    grab = int(np.flatnonzero((uv[:, 0] == 0) & np.isclose(uv[:, 1], 0.02))[0])
    pinned = np.isclose(uv[:, 0], 0.2)
    w, d_grab, d_pin, _ = drag_weights(model, grab, pinned)
    row = np.flatnonzero(np.isclose(uv[:, 1], 0.02))
    row = row[np.argsort(uv[row, 0])]
    assert w[grab] == 1 and (w[pinned] == 0).all()
    assert (np.diff(w[row]) <= 1e-12).all()
    t = d_pin / (d_grab + d_pin)
    np.testing.assert_allclose(w[~pinned], smooth_falloff(t[~pinned]), atol=1e-12)
    lin, *_ = drag_weights(model, grab, pinned, falloff="linear")
    np.testing.assert_allclose(lin[~pinned], t[~pinned], atol=1e-12)
    assert w[row[-2]] < 0.25 * lin[row[-2]]  # next to the pin: the smooth falloff is nearly flat


def test_pins_stop_the_propagation():
    """A column of pins across the strip cuts it: the far side is not reached (weight 0, no parent)."""
    model, uv = _sheet()
    pinned = np.isclose(uv[:, 0], 0.1)
    w, d_grab, _, parent = drag_weights(model, 0, pinned)
    beyond = uv[:, 0] > 0.1 + 1e-9
    assert np.isinf(d_grab[beyond]).all() and (w[beyond] == 0).all() and (parent[beyond] == -1).all()
    assert (w[uv[:, 0] < 0.1 - 1e-9] > 0).all()


# -- the body part's axis -----------------------------------------------------------------------------------------
def test_body_axis_of_the_torso_and_the_forearm(body, body_collider):
    """At the front of the hips the axis is the torso's (near vertical) through the middle of the hips; on the
    forearm it runs along the forearm, through the arm."""
    surface = body.mesh.vertices
    hip = surface[np.argmax(surface[:, 2] - 10 * np.abs(surface[:, 1] - 0.9) - 10 * np.abs(surface[:, 0]))]
    axis, centre = body_axis(body_collider, hip)
    assert abs(axis[1]) > np.cos(np.radians(15))
    assert abs(centre[0]) < 0.01 and abs(centre[1] - hip[1]) < 0.02 and centre[2] < hip[2] - 0.08
    j = body.rig.joints
    elbow, wrist = j[INDEX["l_elbow"]], j[INDEX["l_wrist"]]
    mid = 0.5 * (elbow + wrist)
    on_arm = surface[np.argmin(np.linalg.norm(surface - mid, axis=1))]
    axis, centre = body_axis(body_collider, on_arm)
    fore = (wrist - elbow) / np.linalg.norm(wrist - elbow)
    assert abs(axis @ fore) > np.cos(np.radians(10))
    assert np.linalg.norm(np.cross(centre - mid, fore)) < 0.02  # the centre lies on the forearm's line
