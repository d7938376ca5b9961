"""Strokes against a pattern and a body: pattern-side checks, projection, laser hits, the packaged kimono
strokes."""

from __future__ import annotations

import numpy as np
import pytest

from kitsuke.dressing import (
    BodyStroke,
    PatternStroke,
    StrokePair,
    Strokes,
    check_strokes,
    load_packaged_strokes,
    resolve_strokes,
    triangles_crossed,
)
from kitsuke.errors import InputError
from kitsuke.pattern import Curve, Pattern, Piece, default_kimono, mesh_pattern

SRC = "strokes.json"


def one(pattern_points, body: BodyStroke, piece="migoro_left", sid=5) -> Strokes:
    return Strokes([StrokePair(sid, PatternStroke(piece, pattern_points), body)], source=SRC)


def chest_points() -> BodyStroke:
    return BodyStroke(points=[[0.07, 1.30, 0.12], [0.07, 1.10, 0.13]])


# -- pattern side --------------------------------------------------------------------------------------------
def test_missing_piece(kimono):
    s = one([[5, 120], [5, 140]], chest_points(), piece="sleeve")
    with pytest.raises(InputError, match=r"stroke 5: pattern piece 'sleeve' is not in pattern 'kimono'") as e:
        check_strokes(s, kimono)
    assert e.value.path == SRC


def test_point_outside_piece(kimono):
    # migoro_left is 31 cm wide: x = 33 lies 2 cm outside; x = 31.05 is within the 1 mm tolerance.
    check_strokes(one([[31.05, 120], [20, 140]], chest_points()), kimono)
    with pytest.raises(InputError, match=r"stroke 5: pattern point 1 \(33.0, 140.0\) cm lies 2.0 cm outside"):
        check_strokes(one([[20, 120], [33, 140]], chest_points()), kimono)


def test_stroke_leaving_a_concave_piece(kimono):
    # Both ends on migoro_left, but the straight segment between them crosses the neck opening.
    s = one([[3.0, 140.0], [3.0, 163.0]], chest_points())
    with pytest.raises(InputError, match=r"stroke 5: pattern stroke leaves piece 'migoro_left' between points 0 and 1"):
        check_strokes(s, kimono)


def test_curved_outline_is_honoured():
    # A rectangle topped by a half-disc of radius 10 (edge 2 bulges upwards): (0, 9.5) is inside the curve
    # though
    # outside the polygon of the corners; (0, 10.5) is 0.5 cm beyond the arc.
    piece = Piece("disc", [[-10, -5], [10, -5], [10, 0], [-10, 0]], {2: Curve("circle", [[0.5, -0.5]])})
    pattern = Pattern("p", [piece])
    check_strokes(one([[0, 1], [0, 9.5]], chest_points(), piece="disc"), pattern)
    with pytest.raises(InputError, match=r"lies 0.5 cm outside piece 'disc'"):
        check_strokes(one([[0, 1], [0, 10.5]], chest_points(), piece="disc"), pattern)


def test_crossing_no_triangle_of_the_mesh(kimono, kimono_mesh):
    s = one([[5, 120], [5, 140]], chest_points())
    check_strokes(s, kimono, pattern_mesh=kimono_mesh)
    # A mesh of another pattern whose piece has the same name but lies elsewhere.
    other = Pattern("other", [Piece("migoro_left", [[100, 0], [130, 0], [130, 30], [100, 30]])])
    with pytest.raises(InputError, match=r"stroke 5: pattern stroke crosses no triangle of piece 'migoro_left'"):
        check_strokes(s, kimono, pattern_mesh=mesh_pattern(other, edge_length=5.0))
    lonely = Pattern("other", [Piece("okumi", [[0, 0], [30, 0], [30, 30]])])
    with pytest.raises(InputError, match=r"stroke 5: piece 'migoro_left' is not in the meshed pattern"):
        check_strokes(s, kimono, pattern_mesh=mesh_pattern(lonely, edge_length=5.0))


# -- body side -----------------------------------------------------------------------------------------------
def test_points_1cm_off_the_body_land_on_it_on_their_side(body, body_surface, kimono):
    rng = np.random.default_rng(0)
    v, vn = body.mesh.vertices, body.mesh.vertex_normals
    # Vertices on the torso, where the surface is smooth and 1 cm out is unambiguous.
    torso = np.flatnonzero((v[:, 1] > 0.95) & (v[:, 1] < 1.35) & (np.abs(v[:, 0]) < 0.12))
    pick = rng.choice(torso, size=200, replace=False)
    drawn = v[pick] + 0.01 * vn[pick]
    s = Strokes([StrokePair(1, PatternStroke("migoro_left", [[5, 120], [5, 140]]), BodyStroke(points=drawn))])
    r = resolve_strokes(s, kimono, body_surface).pair(1).body
    assert r.resolved and r.surface_points.shape == (200, 3)
    # On the surface: the reported face and barycentric coordinates give back the point.
    on = body_surface.evaluate(r.faces, r.barycentric)
    np.testing.assert_allclose(on, r.surface_points, atol=1e-9)
    assert np.all(r.barycentric >= 0) and np.allclose(r.barycentric.sum(axis=1), 1.0)
    # On the face's plane (so on the surface, the barycentric coordinates being inside the triangle).
    tri = body_surface.vertices[body_surface.faces[r.faces]]
    off_plane = np.einsum("ij,ij->i", r.surface_points - tri[:, 0], body_surface.normals_at(r.faces))
    assert np.abs(off_plane).max() < 1e-9
    # Back near the vertex they were lifted from (curvature moves the closest point a little, never to another
    # part of the body), about 1 cm away.
    moved = np.linalg.norm(r.surface_points - v[pick], axis=1)
    assert np.median(moved) < 1e-3 and moved.max() < 0.01
    # Never farther than the vertex itself (1 cm), and 1 cm for most (less in hollows, where another face is
    # nearer).
    assert r.surface.distance.max() <= 0.01 + 1e-12 and np.median(r.surface.distance) == pytest.approx(0.01, abs=1e-4)
    # On the right side: the surface faces the drawn point.
    normals = body_surface.normals_at(r.faces)
    assert (np.einsum("ij,ij->i", drawn - r.surface_points, normals) > 0).all()


def test_body_point_too_far(body_surface, kimono):
    s = one([[5, 120], [5, 140]], BodyStroke(points=[[0.07, 1.30, 0.12], [0.07, 1.10, 0.30]]))
    with pytest.raises(
        InputError, match=r"stroke 5: body point 1 is 1[0-9].\d cm from the body surface \(at most 5 cm\)"
    ):
        resolve_strokes(s, kimono, body_surface)
    s.target = "garment"
    with pytest.raises(InputError, match=r"from the garment surface"):
        resolve_strokes(s, kimono, body_surface)


def test_far_points_are_cheap_and_exact(body_surface):
    # Points metres away (where trimesh's closest_point blows up) go through the AABB like near ones.
    far = np.array([[5.0, 1.0, 0.0], [0.0, 10.0, 0.0], [0.0, 1.0, -7.0]])
    sp = body_surface.closest(far)
    d_brute = np.linalg.norm(far[:, None] - body_surface.vertices[None], axis=2).min(axis=1)
    assert np.all(sp.distance <= d_brute + 1e-12) and np.all(sp.distance > d_brute - 0.01)


def laser(hit, ys=(1.25, 1.20, 1.15)):
    rays = [[0.0, y, 2.0, 0.0, 0.0, -1.0] for y in ys]
    return BodyStroke(rays=rays, hit=hit)


def test_laser_first_and_last_through_the_chest(body_surface, kimono):
    s = Strokes(
        [
            StrokePair(1, PatternStroke("migoro_left", [[5, 120], [5, 130]]), laser("first")),
            StrokePair(2, PatternStroke("migoro_left", [[5, 170], [5, 180]]), laser("last")),
        ]
    )
    r = resolve_strokes(s, kimono, body_surface)
    front, back = r.pair(1).body, r.pair(2).body
    assert (front.surface_points[:, 2] > back.surface_points[:, 2] + 0.1).all()  # the chest is > 10 cm deep
    for b in (front, back):
        np.testing.assert_allclose(b.surface_points[:, [0, 1]], [[0, y] for y in (1.25, 1.20, 1.15)], atol=1e-9)
        assert body_surface.closest(b.surface_points).distance.max() < 1e-6  # on the surface
        assert np.allclose(b.surface.distance, 2.0 - b.surface_points[:, 2])  # distance along the ray
    # The front faces the ray's origin, the back faces away from it.
    assert (body_surface.normals_at(front.faces)[:, 2] > 0).all()
    assert (body_surface.normals_at(back.faces)[:, 2] < 0).all()


def test_laser_that_misses(body_surface, kimono):
    s = one([[5, 120], [5, 140]], BodyStroke(rays=[[0, 1.2, 2, 0, 0, -1], [0, 1.2, 2, 0, 0, 1]], hit="first"))
    with pytest.raises(InputError, match=r"stroke 5: laser ray 1 hits nothing on the body surface") as e:
        resolve_strokes(s, kimono, body_surface)
    assert e.value.path == SRC


def test_body_stroke_of_zero_length(body_surface, kimono):
    s = one([[5, 120], [5, 140]], BodyStroke(points=[[0.0, 1.2, 0.2], [0.0, 1.2, 0.2001]]))
    with pytest.raises(InputError, match=r"stroke 5: body stroke has zero length"):
        resolve_strokes(s, kimono, body_surface)


def test_resolve_checks_the_pattern_first(body_surface, kimono):
    with pytest.raises(InputError, match="is not in pattern"):
        resolve_strokes(one([[5, 120], [5, 140]], chest_points(), piece="nope"), kimono, body_surface)


# -- the packaged strokes ------------------------------------------------------------------------------------
def test_packaged_kimono_strokes_resolve_on_the_default_body(body, body_surface):
    kimono = default_kimono()  # the standard kimono cut to the default body
    kimono_mesh = mesh_pattern(kimono, edge_length=3.0)
    s = load_packaged_strokes("kimono_default")
    assert s.target == "body" and len(s) >= 8 and s.ids == list(range(1, len(s) + 1))
    assert any(p.body.is_laser and p.body.hit == "first" for p in s.pairs)
    assert any(p.body.is_laser and p.body.hit == "last" for p in s.pairs)
    r = resolve_strokes(s, kimono, body_surface, pattern_mesh=kimono_mesh)
    assert r.resolved
    pieces = {p.pattern.piece for p in r.pairs}
    assert {"migoro_left", "migoro_right", "sode_left", "sode_right"} <= pieces
    for p in r.pairs:
        assert len(triangles_crossed(kimono_mesh, p.pattern)) >= 3
        # Drawn on the surface (projection moves them < 1 mm) and as long on the body as on the pattern (3 %):
        # the wrap transfers by arc length, so a mismatch would stretch the cloth.
        if not p.body.is_laser:
            assert p.body.surface.distance.max() < 1e-3
        body_len = p.body.resample(body_surface, 100).points
        length_cm = 100 * np.linalg.norm(np.diff(body_len, axis=0), axis=1).sum()
        assert length_cm == pytest.approx(p.pattern.length_cm, rel=0.03), p.id
    # Mirror symmetry of the body and the kimono: each right stroke has a left twin (x -> -x).
    by_piece = {}
    for p in r.pairs:
        by_piece.setdefault(p.pattern.piece, []).append(p.body.surface_points)
    for right, left in zip(by_piece["migoro_right"], by_piece["migoro_left"]):
        np.testing.assert_allclose(right * [-1, 1, 1], left, atol=2e-3)
    # Sleeves run along the top of the arms, from the upper arm towards the wrist.
    from kitsuke.skeleton import INDEX

    j = body.rig.joints
    for side in ("l", "r"):
        sleeve = by_piece[f"sode_{'left' if side == 'l' else 'right'}"][0]
        start, end = sleeve[0], sleeve[-1]
        assert np.linalg.norm(end - j[INDEX[f"{side}_wrist"]]) < np.linalg.norm(start - j[INDEX[f"{side}_wrist"]])
        assert abs(start[0]) > abs(j[INDEX[f"{side}_shoulder"]][0])
