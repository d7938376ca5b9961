"""The wrap on strokes a hand would draw: either way round, longer or shorter than the pattern stroke; and its
honest outcome: a result that is not a garment on the body raises ComputationError naming what failed."""

from __future__ import annotations

import re

import numpy as np
import pytest

from kitsuke.dressing import (
    BodyStroke,
    PatternStroke,
    SettleSettings,
    StrokePair,
    Strokes,
    WrapParams,
    check_strokes,
    on_body_failures,
    resolve_strokes,
    target_misses,
    wrap,
)
from kitsuke.errors import ComputationError, InputError
from kitsuke.geometry.surface import Surface
from kitsuke.metrics import QualityTargets
from kitsuke.pattern import EdgeRef, Pattern, Piece, Seam, sliver_pieces

from .test_wrap import _sphere, _square

PARAMS = WrapParams(edge_length_cm=2.0, settle=SettleSettings(iterations=40))


def _meridian(radius_m: float, length_m: float, up: bool = True) -> np.ndarray:
    """Points up (or down) the front of a sphere (+z), centred on its equator, `length_m` long."""
    ang = np.linspace(-0.5, 0.5, 9) * length_m / radius_m
    pts = np.c_[np.zeros_like(ang), radius_m * np.sin(ang), radius_m * np.cos(ang)]
    return pts if up else pts[::-1]


def _upright(body_points: np.ndarray) -> Strokes:
    """A 16 cm stroke up the middle of the 20 cm square (pattern y is up)."""
    return Strokes(
        [StrokePair(1, PatternStroke("square", [[10.0, 2.0], [10.0, 18.0]]), BodyStroke(points=body_points))]
    )


@pytest.fixture(scope="module")
def sphere():
    return _sphere(0.3)


@pytest.fixture(scope="module")
def drawn_up(sphere):
    return wrap(sphere, _square(), _upright(_meridian(0.3, 0.16)), params=PARAMS)


def test_a_body_stroke_drawn_the_other_way_is_taken_the_right_way(sphere, drawn_up):
    down = wrap(sphere, _square(), _upright(_meridian(0.3, 0.16, up=False)), params=PARAMS)
    assert [t.reversed for t in down.tracks] == [True] and [t.reversed for t in drawn_up.tracks] == [False]
    # The pattern's top lies at the top either way.
    top = [g.positions[g.pattern_vertex[np.argmax(g.pattern_mesh.vertices_cm[:, 1])], 1] for g in (drawn_up, down)]
    assert top[0] > 0.05 and top[1] == pytest.approx(top[0], abs=0.01)  # measured 0.090 m both
    assert down.report.strain_max < 0.3 and down.max_stroke_residual_m < 0.01


@pytest.mark.parametrize("ratio", [0.7, 1.3])
def test_the_cloth_keeps_its_own_length_whatever_the_body_stroke_length(sphere, drawn_up, ratio):
    """A body stroke 0.7 or 1.3 times its pattern stroke says where the cloth lies, not how long it is: the
    placed cloth is not squeezed or stretched to fit it (with the paper's arc-length correspondence the shirt
    ended at 31 % max strain for a body stroke 10 % short, 179 % for 30 %)."""
    g = wrap(sphere, _square(), _upright(_meridian(0.3, 0.16 * ratio)), params=PARAMS)
    assert g.stroke_length_ratio[0] == pytest.approx(ratio, rel=0.03)
    assert g.report.strain_mean < 1.5 * max(drawn_up.report.strain_mean, 0.005)
    assert g.report.strain_max < 0.3
    assert g.max_stroke_residual_m < 0.01  # the cloth's stroke lies along the drawn one (continued past its ends)


def test_strokes_that_no_garment_can_meet_raise_and_name_what_failed(sphere):
    """Two strokes 16 cm apart on the square, drawn on opposite sides of the sphere (60 cm apart): no square can
    lie there. The wrap raises ComputationError naming the failure, with the unusable garment for inspection."""
    back = _meridian(0.3, 0.16) * [1.0, 1.0, -1.0]
    strokes = Strokes(
        [
            StrokePair(1, PatternStroke("square", [[2.0, 2.0], [2.0, 18.0]]), BodyStroke(points=_meridian(0.3, 0.16))),
            StrokePair(2, PatternStroke("square", [[18.0, 2.0], [18.0, 18.0]]), BodyStroke(points=back)),
        ]
    )
    with pytest.raises(ComputationError, match=r"^wrap: not a garment on the body: (stroke \d|piece square)") as e:
        wrap(sphere, _square(), strokes, params=PARAMS)
    garment = e.value.result
    assert garment is not None and on_body_failures(garment, sphere)
    # check=False returns it, for callers that judge it themselves.
    assert wrap(sphere, _square(), strokes, params=PARAMS, check=False).n_vertices == garment.n_vertices


def test_cloth_flung_far_from_the_body_is_not_a_garment(drawn_up):
    """A garment on the body but for one flap half a metre off it (found written with exit 0 on a corpus design)."""
    import copy

    flung = copy.copy(drawn_up)
    flung.positions = drawn_up.positions.copy()
    centre = flung.positions.mean(axis=0)
    flung.positions[0] = centre + 0.9 * (flung.positions[0] - centre) / np.linalg.norm(flung.positions[0] - centre)
    failures = on_body_failures(flung, _sphere(0.3))
    assert failures[0].startswith("piece square: cloth 60 cm from the body")  # (and torn, where it was pulled)
    # where on the body, then where in space (kitsuke.body.regions names the place)
    assert re.match(r"piece square: cloth 60 cm from the body (at|on|under) the [a-z ]+, at \(.+\) m$", failures[0])
    assert on_body_failures(drawn_up, _sphere(0.3)) == []


def test_cloth_resting_on_the_floor_is_not_flung(drawn_up):
    """A gown's train pools on the floor half a metre from the feet: worn, not flung. The floor is the body's
    lowest point; the same vertex 60 cm off the body in the air is (the test above)."""
    import copy

    sphere = _sphere(0.3)
    pooled = copy.copy(drawn_up)
    pooled.positions = drawn_up.positions.copy()
    pooled.positions[0] = [0.6, sphere.vertices[:, 1].min() + 0.01, 0.5]
    failures = on_body_failures(pooled, sphere)
    assert not any("from the body" in f for f in failures)
    assert any("is torn" in f for f in failures)  # one vertex pulled that far still tears its edges


def test_a_piece_on_the_other_side_from_its_placement_is_not_a_garment(drawn_up):
    """The square lies on the sphere's front. Without a stroke on it, placed at the sphere's back, it is on the
    wrong side (a corpus skirt's front was found hanging off the back left of the hip, written as out of
    target); placed at the front, it is not. With its stroke, the stroke says where it goes, whatever the
    placement (a garment may be worn turned round on purpose)."""
    import copy
    import dataclasses

    pm = drawn_up.pattern_mesh
    at = drawn_up.positions[drawn_up.pattern_vertex]
    for placed_z, tracks, wrong in ((1.0, [], False), (-1.0, [], True), (-1.0, drawn_up.tracks, False)):
        g = copy.copy(drawn_up)
        g.tracks = tracks
        g.pattern_mesh = dataclasses.replace(pm, positions_m=at * [1.0, 1.0, placed_z], placed=np.ones(1, dtype=bool))
        expected = ["piece square ended at the body's front; its placement puts it at the back"] if wrong else []
        assert on_body_failures(g, _sphere(0.3)) == expected


def test_a_piece_left_behind_when_the_strokes_turned_the_garment_is_named_with_the_turn():
    """Two pieces placed at the front and at the left; the stroked one was worn at the back (the strokes turned
    the garment round), the other stayed at the left: it should have turned to the right, and the message says
    where the turned placement puts it, not where the untouched placement does (which would read "ended at the
    left; its placement puts it at the left")."""
    from types import SimpleNamespace

    from kitsuke.dressing.outcome import wrong_side
    from kitsuke.geometry import TriMesh

    square = np.array([[-0.05, 0.0, 0.0], [0.05, 0.0, 0.0], [0.05, 0.1, 0.0], [-0.05, 0.1, 0.0]])
    front = square + [0.0, 1.0, 0.3]
    left = square[:, [2, 1, 0]] + [0.3, 1.0, 0.0]
    back, right = front * [1.0, 1.0, -1.0], left * [-1.0, 1.0, 1.0]
    pm = SimpleNamespace(
        piece_names=["a", "b"], n_vertices=8, placed=np.ones(2, dtype=bool),
        piece_vertices=np.array([[0, 4], [4, 8]]), positions_m=np.concatenate([front, left]),
    )  # fmt: skip
    body = TriMesh(np.array([[-0.2, 0.0, -0.1], [0.2, 0.0, -0.1], [0.0, 1.8, 0.1]]), np.array([[0, 1, 2]]))
    faces = np.array([[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]])

    def worn(b: np.ndarray) -> SimpleNamespace:
        return SimpleNamespace(
            pattern_mesh=pm, pattern_vertex=np.arange(8), positions=np.concatenate([back, b]), faces=faces,
            piece_faces=np.array([[0, 2], [2, 4]]), tracks=[SimpleNamespace(faces=np.array([0]))],
        )  # fmt: skip

    assert wrong_side(worn(right), body) == []  # turned with its stroked neighbour: fine
    assert wrong_side(worn(left), body) == [
        "piece b ended at the body's left; its placement, turned +180° as the stroked pieces were, puts it at the right"
    ]


def test_a_garment_on_the_body_reports_the_targets_it_misses(drawn_up):
    assert on_body_failures(drawn_up, _sphere(0.3)) == []
    strict = QualityTargets(max_strain=1e-4, stroke_residual_mm=0.1)
    misses = target_misses(drawn_up, strict)
    assert any(m.startswith("max edge strain") for m in misses)
    assert any("farther than 0.1 mm from where drawn" in m for m in misses)
    assert drawn_up.summary()["targets_missed"] == target_misses(drawn_up)


def _with_hem_strip(height_cm: float) -> Pattern:
    """The square with a strip `height_cm` tall sewn under its bottom edge, as GarmentCode's sampler sews a cuff
    0.25 mm tall under a trouser leg."""
    square = _square()
    strip = Piece("strip", np.array([[0.0, -height_cm], [20.0, -height_cm], [20.0, 0.0], [0.0, 0.0]]))
    return Pattern("sheet", [*square.pieces, strip], [Seam(EdgeRef("square", 0), EdgeRef("strip", 2))])


def test_a_sliver_is_left_out_of_the_wrap_and_said(sphere, drawn_up):
    """A piece narrower on average than 5 mm meshes into needle triangles a fraction of a millimetre across that
    any wrinkle tears (the sampler's 0.25 mm cuffs failed their wraps as torn): the wrap leaves it out and says so;
    a 1 cm strip is worn."""
    thin = _with_hem_strip(0.025)
    assert sliver_pieces(thin) == {"strip": pytest.approx(0.025, rel=0.01)}
    assert thin.without(["strip"]).piece_names == ["square"] and thin.without(["strip"]).seams == []
    g = wrap(sphere, thin, _upright(_meridian(0.3, 0.16)), params=PARAMS)
    assert g.piece_names == ["square"] and list(g.left_out) == ["strip"]
    assert g.summary()["left_out_pieces"] == {"strip": {"mean_width_mm": pytest.approx(0.25, rel=0.01)}}
    assert g.n_vertices == drawn_up.n_vertices and not on_body_failures(g, sphere)
    wide = wrap(sphere, _with_hem_strip(1.0), _upright(_meridian(0.3, 0.16)), params=PARAMS)
    assert wide.piece_names == ["square", "strip"] and wide.left_out == {}
    # A stroke drawn on the sliver is refused, naming it.
    on_strip = Strokes(
        [StrokePair(1, PatternStroke("strip", [[2.0, -0.01], [18.0, -0.01]]), BodyStroke(points=_meridian(0.3, 0.16)))]
    )
    with pytest.raises(InputError, match="stroke 1 is drawn on piece 'strip', a sliver 0.25 mm wide"):
        wrap(sphere, thin, on_strip, params=PARAMS)
    # ... and so it is by the check that `kitsuke dress` and `kitsuke strokes check` run before loading the body.
    with pytest.raises(InputError, match="stroke 1 is drawn on piece 'strip', a sliver 0.25 mm wide"):
        check_strokes(on_strip, thin)
    with pytest.raises(InputError, match="a sliver 0.25 mm wide"):  # `kitsuke strokes check` resolves them
        resolve_strokes(on_strip, thin, Surface(sphere))
    check_strokes(_upright(_meridian(0.3, 0.16)), thin)  # a stroke on the square is fine
