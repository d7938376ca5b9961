"""Body collision: nearest-point tracking against brute force, push-out, capsules, and cloth on the default body."""

from __future__ import annotations

import numpy as np
import pytest

from kitsuke.cloth import BodyCollider, ClothModel, ClothParams, ClothState, collide, relax, sweep, track
from kitsuke.cloth import _collide_kernels as CK
from kitsuke.cloth._collide import SWEEP_MIN_M
from kitsuke.cloth._shapes import grid_sheet
from kitsuke.errors import InputError
from kitsuke.geometry import TriMesh
from kitsuke.metrics import penetration

from . import reference as ref
from .conftest import icosphere


def test_closest_on_triangle_matches_reference(rng):
    for _ in range(300):
        tri = rng.normal(size=(3, 3))
        p = rng.normal(size=3) * 2
        cx, cy, cz, b0, b1, b2, region = CK.closest_on_triangle(p[0], p[1], p[2], tri, 0, 1, 2)
        want = ref.closest_on_triangle(p, *tri)
        np.testing.assert_allclose([cx, cy, cz], want, atol=1e-9)
        np.testing.assert_allclose(b0 * tri[0] + b1 * tri[1] + b2 * tri[2], want, atol=1e-9)
        assert b0 + b1 + b2 == pytest.approx(1.0) and min(b0, b1, b2) >= -1e-12
        assert (region == 0) == (min(b0, b1, b2) > 1e-12)


def bumpy_sphere() -> TriMesh:
    """A non-convex closed surface: a sphere with dents and bumps (radius 10 cm +- 2 cm)."""
    s = icosphere(0.1, 4)
    v = s.vertices
    d = v / np.linalg.norm(v, axis=1, keepdims=True)
    r = 0.1 + 0.02 * np.sin(3 * d[:, 0]) * np.cos(4 * d[:, 1]) * np.sin(2 * d[:, 2] + 1)
    return TriMesh(d * r[:, None], s.faces)


def point_cloud_model(points: np.ndarray, params: ClothParams | None = None) -> tuple[ClothModel, ClothState]:
    """Cloth vertices to track, grouped by three into separate triangles (which only make them active)."""
    n = len(points)
    faces = np.arange(n).reshape(-1, 3)
    corners = np.tile([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]], (n // 3, 1, 1))
    model = ClothModel.from_corners(faces, corners, params=params)
    return model, ClothState.new(model, points)


@pytest.mark.parametrize("shape", ["sphere", "bumpy"])
def test_tracking_matches_brute_force(shape, rng):
    """Global search, then walks after small moves, against the nearest point over all faces. On a convex surface
    the walk's local minimum is the global one; on a bumpy one it may settle in a neighbouring shallow dent (a
    Skin-style tracker's nature, as it is for points inside): then it must still be within 0.5 mm of the true
    distance, and rare."""
    mesh = icosphere(0.1, 3) if shape == "sphere" else bumpy_sphere()
    col = BodyCollider.from_mesh(mesh)
    d = ref.unit(rng.normal(size=(60, 3)))
    pts = d * rng.uniform(0.105 if shape == "sphere" else 0.06, 0.15, (60, 1))
    model, state = point_cloud_model(pts)
    assert track(model, state, col) == 60  # all new: global searches
    near = exact = 0
    for step in range(4):
        if step:
            state.positions += rng.normal(0, 0.004, state.positions.shape)  # small moves: walks
            track(model, state, col)
        c = state.contacts
        for i in range(len(pts)):
            f, point, dist = ref.closest_on_mesh(state.positions[i], mesh.vertices, mesh.faces)
            if dist > model.params.track_distance_m:
                continue  # far away only a lower bound matters (see the next test)
            near += 1
            np.testing.assert_allclose(mesh.vertices[mesh.faces[c.face[i]]].T @ c.bary[i], c.point[i], atol=1e-9)
            assert abs(c.distance[i]) == pytest.approx(np.linalg.norm(state.positions[i] - c.point[i]), abs=1e-12)
            assert abs(c.distance[i]) - dist < 5e-4
            if np.allclose(c.point[i], point, atol=1e-9):
                exact += 1
            elif step == 0 or shape == "sphere":
                raise AssertionError(f"vertex {i}: tracked {c.point[i]}, nearest {point}")
    assert near > 100 and exact >= 0.9 * near
    # Signs: inside the (closed) surface negative, by the generalised winding number.
    import igl

    inside = igl.winding_number(mesh.vertices, mesh.faces, state.positions) > 0.5
    np.testing.assert_array_equal(state.contacts.distance < 0, inside)


def test_far_vertex_is_searched_again_when_it_may_come_near():
    """Two separate spheres: a vertex tracked far from sphere A moves next to sphere B. Its walk cannot leave A,
    but it has moved farther than its distance from the body at its last trusted result, so it may be in contact:
    a global search finds B."""
    a, b = icosphere(0.1, 2), icosphere(0.1, 2, centre=(1.0, 0.0, 0.0))
    two = TriMesh(np.r_[a.vertices, b.vertices], np.r_[a.faces, b.faces + len(a.vertices)])
    col = BodyCollider.from_mesh(two)
    model, state = point_cloud_model(np.array([[0.0, 0.5, 0.0], [0.0, 0.6, 0.0], [0.0, 0.7, 0.0]]))
    track(model, state, col)
    assert state.contacts.distance[0] == pytest.approx(0.4, abs=2e-3)
    state.positions[0] = [0.01, 0.49, 0.0]  # a small move, still far: the walk result stands
    assert track(model, state, col) == 0
    state.positions[0] = [1.0, 0.103, 0.0]  # next to sphere B
    assert track(model, state, col) == 1
    assert state.contacts.face[0] >= len(a.faces)
    assert state.contacts.distance[0] == pytest.approx(0.003, abs=1.5e-3)
    assert state.contacts.normal[0, 1] > 0.99


def test_moved_body_keeps_tracking(sphere):
    col = BodyCollider.from_mesh(sphere)
    model, state = point_cloud_model(np.array([[0.0, 0.104, 0.0], [0.104, 0.0, 0.0], [0.0, 0.3, 0.0]]))
    track(model, state, col)
    moved = col.moved(sphere.vertices + [0.0, 0.01, 0.0])  # the body rose 1 cm: the first vertex is now inside
    state.contacts.forget_anchors()
    assert track(model, state, moved) == 1  # only the far vertex is searched again; the near ones walk
    assert state.contacts.distance[0] == pytest.approx(-0.006, abs=1e-3)
    collide(model, state, moved)
    track(model, state, moved)
    assert state.contacts.distance[0] == pytest.approx(model.params.contact_offset_m, abs=2e-4)


def test_a_moving_body_finds_the_same_nearest_points_without_a_tree(body, body_collider, rng):
    """On a moved body (a simulation's every frame) a few global searches walk from the nearest body vertex
    instead of building a search tree: the same nearest points as the tree's, on a real body, near and far."""
    v = body.mesh.vertices
    bent = v + np.c_[0.03 * np.sin(4 * v[:, 1]), 0.01 * np.ones(len(v)), 0.02 * np.cos(3 * v[:, 0])]  # another pose
    moved = body_collider.moved(bent)
    assert moved.moving and moved._surface is None
    k = rng.choice(len(bent), 300, replace=False)
    off = np.abs(rng.normal(size=(300, 1))) * rng.choice([0.002, 0.02, 0.1], size=(300, 1))  # near and far, outside
    pts = bent[k] + moved.vertex_normals[k] * off + rng.normal(size=(300, 3)) * 0.003
    model, state = point_cloud_model(pts)
    assert track(model, state, moved) == len(pts)  # every vertex new: a global search each
    assert moved._surface is None  # found without building the tree
    _, _, exact = moved.nearest(pts)
    err = np.abs(state.contacts.distance) - exact
    assert err.min() > -1e-9  # never nearer than the true nearest point (it is a point of the surface)
    # the same point for 97 % here; the others stop where the surface curves back (a walk's local nearest point)
    assert (err < 1e-6).mean() > 0.95 and err.max() < 2e-3


def test_collider_surface_is_built_once_and_shared(sphere, rng):
    """The wrap places its strokes with the collider's own Surface (one AABB tree per body, not one per wrap);
    a mesh in another pose gets a Surface of its own. `nearest` answers from the same tree."""
    col = BodyCollider.from_mesh(sphere)
    assert col.surface is col.surface
    assert col.surface_for(TriMesh(sphere.vertices.copy(), sphere.faces.copy())) is col.surface
    other = col.surface_for(TriMesh(sphere.vertices * 1.1, sphere.faces))
    assert other is not col.surface
    pts = rng.normal(size=(20, 3)) * 0.2
    face, point, dist = col.nearest(pts)
    brute = np.array(
        [min(np.linalg.norm(p - ref.closest_on_triangle(p, *sphere.vertices[f])) for f in sphere.faces) for p in pts]
    )
    np.testing.assert_allclose(dist, brute, atol=1e-9)
    np.testing.assert_allclose(np.linalg.norm(point - pts, axis=1), dist, atol=1e-9)
    assert np.all(other.closest(pts).distance > 0) and not np.allclose(other.closest(pts).distance, dist)


def test_collider_rejects_open_mesh(sphere):
    with pytest.raises(InputError, match="not closed"):
        BodyCollider.from_mesh(TriMesh(sphere.vertices, sphere.faces[1:]), source="holey.obj")
    flipped = sphere.faces.copy()
    flipped[0] = flipped[0, ::-1]
    with pytest.raises(InputError, match="holey.obj"):
        BodyCollider.from_mesh(TriMesh(sphere.vertices, flipped), source="holey.obj")
    with pytest.raises(InputError, match="capsules"):
        BodyCollider.from_mesh(sphere, capsule_ends=np.zeros((2, 3)), capsule_radii=np.zeros((2, 2)))


def test_push_out_moves_inside_vertices_out_and_keeps_pins(sphere, sphere_collider, rng):
    pts = ref.unit(rng.normal(size=(42, 3))) * rng.uniform(0.05, 0.099, (42, 1))
    model, state = point_cloud_model(pts)
    state.pinned[:6] = True
    stats = collide(model, state, sphere_collider)
    assert stats.pushed == 36 and stats.deepest_m > 0.0
    np.testing.assert_array_equal(state.positions[:6], pts[:6])
    assert penetration(state.positions[6:], sphere, threshold_m=0.0).count == 0
    track(model, state, sphere_collider)
    np.testing.assert_allclose(state.contacts.distance[6:], model.params.contact_offset_m, atol=2e-4)


def test_sweep_stops_a_move_that_would_be_pushed_out_through_the_far_side(sphere, sphere_collider):
    # Moves along x at heights y into a 10 cm sphere from 20 cm before it. Rows 0-4 end 4-8 cm deep past its
    # middle (the push-out would take them out the far side): cut back to where they went in. Kept: 5 ends past
    # the sphere (through and out), 6 passes beside it, 7 ends before its middle (pushed back out the near side),
    # 8 ends 5 mm under the far side (cloth sliding round a body), 9 is short, 10 is held.
    y = np.array([-0.04, -0.02, 0.0, 0.02, 0.04, 0.0, 0.15, 0.0, 0.0, 0.0, 0.0])
    before = np.c_[np.full(11, -0.2), y, np.zeros(11)]
    end_x = np.array([0.05, 0.04, 0.02, 0.04, 0.05, 0.2, 0.2, -0.04, 0.095, 0.0, 0.04])
    after = np.c_[end_x, y, np.zeros(11)]
    before[9, 0] = -0.9 * SWEEP_MIN_M
    movable = np.ones(11, dtype=bool)
    movable[10] = False
    swept = after.copy()
    assert sweep(before, swept.copy(), movable, sphere_collider, below_y=-0.03) == 1  # only the lowest row
    assert sweep(before, swept, movable, sphere_collider) == 5
    np.testing.assert_array_equal(swept[5:], after[5:])
    entry = -np.sqrt(0.1**2 - y[:5] ** 2)  # the sphere's near side (the icosphere's facets lie a little inside it)
    assert np.all(np.abs(swept[:5, 0] - entry) < 3e-3)
    # Collision after it keeps them on the side they came from; without the sweep it finishes the move.
    for positions, side in ((swept, -1), (after, 1)):
        model, state = point_cloud_model(positions[:6])
        collide(model, state, sphere_collider)
        assert np.all(np.sign(state.positions[:5, 0]) == side)


def test_capsule_vertices_pushed_to_tapered_surface(rng):
    ends = np.array([[[0.0, 0.0, 0.0], [0.0, 0.3, 0.0]]])
    radii = np.array([[0.05, 0.02]])
    pts = np.c_[rng.uniform(-0.04, 0.04, 200), rng.uniform(0.0, 0.3, 200), rng.uniform(-0.04, 0.04, 200)]
    before = pts.copy()
    movable = np.ones(200, dtype=bool)
    near = np.zeros(200, dtype=np.int64)
    lo, hi = ends.min(axis=1) - 0.05, ends.max(axis=1) + 0.05
    CK.capsule_vertices(pts, movable, ends, radii, lo, hi, 0.0, near)
    assert (near == 1).all()
    t = np.clip(pts[:, 1] / 0.3, 0, 1)
    r_here = 0.05 + t * (0.02 - 0.05)
    dist = np.linalg.norm(pts[:, [0, 2]], axis=1)
    was_in = np.linalg.norm(before[:, [0, 2]], axis=1) < 0.05 + np.clip(before[:, 1] / 0.3, 0, 1) * -0.03
    np.testing.assert_allclose(dist[was_in], r_here[was_in], atol=1e-9)  # radially out, at the same height
    np.testing.assert_array_equal(pts[~was_in], before[~was_in])
    np.testing.assert_allclose(pts[:, 1], before[:, 1], atol=1e-12)


def test_segment_segment_matches_sampling(rng):
    for _ in range(100):
        p1, q1, p2, q2 = rng.normal(size=(4, 3))
        s, t = CK.segment_segment(*p1, *q1, *p2, *q2)
        d = np.linalg.norm(p1 + s * (q1 - p1) - (p2 + t * (q2 - p2)))
        assert d == pytest.approx(ref.segment_segment_distance(p1, q1, p2, q2), abs=1e-6)


def test_edge_through_capsule_is_pushed_out():
    ends = np.array([[[0.0, 0.0, -0.2], [0.0, 0.0, 0.2]]])  # along z
    radii = np.array([[0.03, 0.03]])
    lo, hi = ends.min(axis=1) - 0.03, ends.max(axis=1) + 0.03
    pos = np.array([[-0.05, 0.01, 0.0], [0.05, 0.01, 0.0], [0.0, 0.2, 0.0]])  # edge 0-1 cuts the capsule
    edges = np.array([[0, 1], [1, 2], [0, 2]])
    movable = np.ones(3, dtype=bool)
    before = pos.copy()
    near = np.zeros(3, dtype=np.int64)
    CK.capsule_vertices(pos, movable, ends, radii, lo, hi, 0.1, near)
    np.testing.assert_array_equal(pos, before)  # no vertex inside: vertex collision alone misses it
    np.testing.assert_array_equal(near, [1, 1, 0])  # the far vertex is beyond the margin
    CK.capsule_edges(pos, edges, movable, ends, radii, near)
    s, t = CK.segment_segment(*pos[0], *pos[1], *ends[0, 0], *ends[0, 1])
    gap = np.linalg.norm(pos[0] + s * (pos[1] - pos[0]) - (ends[0, 0] + t * (ends[0, 1] - ends[0, 0])))
    assert gap == pytest.approx(0.03, abs=1e-9)
    assert pos[0, 1] == pytest.approx(0.03) and pos[1, 1] == pytest.approx(0.03)  # lifted straight up


def test_sheet_partly_inside_the_default_body_ends_outside(body, body_collider):
    """A 30 x 30 cm sheet across the belly, its middle 3 cm inside the body: after relaxation with collision no
    vertex is more than 2 mm inside (the SPEC §6 measure)."""
    uv, faces = grid_sheet(21, 21, 0.015)
    model = ClothModel.from_flat(faces, uv)
    pos = np.c_[uv - 0.15, np.zeros(len(uv))] + [0.0, 1.0, 0.0]
    v = body.mesh.vertices
    front = v[(np.abs(v[:, 1] - 1.0) < 0.01) & (np.abs(v[:, 0]) < 0.15), 2].max()
    pos[:, 2] = front - 0.03 + 0.6 * np.sum((uv - 0.15) ** 2, axis=1)  # curved, deepest in the middle
    assert penetration(pos, body.mesh).count > 50
    state = ClothState.new(model, pos)
    relax(model, state, body_collider, iterations=60)
    pen = penetration(state.positions, body.mesh)
    assert pen.count == 0 and pen.deepest_mm <= 2.0


def test_collide_told_what_moved_matches_a_full_collision(body, body_collider, rng):
    """`collide(moved=)` (what a strain limit's sweeps pass): told which vertices moved since the last collision
    (those it pushed among them), it ends with the positions and tracked contacts of a full collision, capsules
    included."""
    uv, faces = grid_sheet(15, 15, 0.02)
    model = ClothModel.from_flat(faces, uv)
    pos = np.c_[uv - 0.14, np.zeros(len(uv))] + [0.0, 1.0, 0.0]
    v = body.mesh.vertices
    pos[:, 2] = v[(np.abs(v[:, 1] - 1.0) < 0.01) & (np.abs(v[:, 0]) < 0.15), 2].max() + 0.002
    state = ClothState.new(model, pos)
    collide(model, state, body_collider)
    moved = (state.positions != pos).any(axis=1)  # what the collision pushed, it tracks again next time
    assert 0 < moved.sum() < model.n_vertices
    shaken = rng.choice(model.n_vertices, 20, replace=False)
    state.positions[shaken] += rng.normal(0.0, 0.01, (20, 3))  # some into the body, some away
    moved[shaken] = True
    full, told = state.copy(), state.copy()
    collide(model, full, body_collider)
    stats = collide(model, told, body_collider, moved=moved)
    assert stats.pushed > 0
    np.testing.assert_array_equal(told.positions, full.positions)
    for name in ("face", "distance", "point"):
        np.testing.assert_array_equal(getattr(told.contacts, name), getattr(full.contacts, name))


def test_floor_keeps_cloth_above_the_ground_and_pins_still(sphere):
    collider = BodyCollider.from_mesh(sphere, floor_y=-0.2)
    pts = np.array(
        [[0.5, -0.5, 0.0], [0.6, -0.199, 0.0], [0.7, -0.3, 0.0], [0.8, 0.4, 0.0], [0.9, 0.0, 0.0], [1, 1, 1.0]]
    )
    model, state = point_cloud_model(pts)
    state.pinned[2] = True
    collide(model, state, collider)
    offset = model.params.contact_offset_m
    np.testing.assert_allclose(state.positions[[0, 1], 1], -0.2 + offset)
    np.testing.assert_array_equal(state.positions[2:], pts[2:])  # pinned, and above the floor
    np.testing.assert_array_equal(state.positions[:, [0, 2]], pts[:, [0, 2]])  # straight up, not sideways


def test_from_body_puts_the_floor_under_the_feet(body, body_collider):
    assert body_collider.floor_y == pytest.approx(body.mesh.vertices[:, 1].min())
    assert BodyCollider.from_body(body, floor=False).floor_y is None
    with pytest.raises(InputError, match="floor_y"):
        BodyCollider.from_mesh(body.mesh, floor_y=float("nan"))


def test_forget_finds_a_vertex_pushed_into_a_neighbouring_surface():
    """Two spheres 1 cm apart (an arm beside the torso): a vertex tracked on A, moved 4 mm into B, is still near A,
    so the walk keeps it on A, outside. `Contacts.forget` makes the next update search globally: it finds B and
    the vertex is pushed out of it."""
    a, b = icosphere(0.1, 3), icosphere(0.1, 3, centre=(0.21, 0.0, 0.0))
    two = TriMesh(np.r_[a.vertices, b.vertices], np.r_[a.faces, b.faces + len(a.vertices)])
    col = BodyCollider.from_mesh(two)
    model, state = point_cloud_model(np.array([[0.104, 0.0, 0.0], [0.0, 0.6, 0.0], [0.0, 0.7, 0.0]]))
    collide(model, state, col)
    assert state.contacts.face[0] < len(a.faces)
    state.positions[0] = [0.114, 0.0, 0.0]  # 4 mm inside B, 14 mm from A
    collide(model, state, col)
    assert state.contacts.face[0] < len(a.faces) and state.contacts.distance[0] > 0  # the walk's blind spot
    assert penetration(state.positions[:1], two).count == 1
    state.contacts.forget()
    collide(model, state, col)
    assert state.contacts.face[0] >= len(a.faces)
    assert penetration(state.positions[:1], two, threshold_m=0.0).count == 0


def test_vertex_grid_finds_the_nearest_body_vertex(body, rng):
    """The moving body's global search starts at the body vertex nearest each cloth vertex, found in a grid of
    cells: the same vertex a pass over all of them finds, near the body and far from it (outside the grid too)."""
    from kitsuke.cloth import _collide_kernels as K

    v = np.ascontiguousarray(body.mesh.vertices, dtype=np.float64)
    cell = 0.037
    origin, dims, start, items = K.vertex_grid(v, cell)
    assert sorted(items) == list(range(len(v))) and start[-1] == len(v)
    near = v[rng.integers(0, len(v), 400)] + rng.normal(size=(400, 3)) * 0.05
    far = rng.uniform(-2.0, 3.0, size=(100, 3))
    for q in np.vstack([near, far]):
        found = K._grid_nearest(q[0], q[1], q[2], v, origin, dims, cell, start, items)
        d = np.linalg.norm(v - q, axis=1)
        assert d[found] == d.min()
