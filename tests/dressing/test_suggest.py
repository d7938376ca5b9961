"""Suggested strokes (`kitsuke strokes suggest`) and strokes changed as a hand would draw them."""

from __future__ import annotations

import numpy as np
import pytest

from kitsuke.body import load_body
from kitsuke.dressing import (
    HandPerturbation,
    SuggestParams,
    arc_length,
    check_strokes,
    perturb_strokes,
    read_strokes,
    resolve_strokes,
    suggest_strokes,
)
from kitsuke.dressing.perturb import scale_polyline
from kitsuke.dressing.suggest import candidate_strokes
from kitsuke.errors import InputError
from kitsuke.geometry.surface import Surface
from kitsuke.pattern import Piece, load_pattern, make_kimono

from ..conftest import DATA

SHIRT = DATA / "pattern" / "shirt_mean_specification.json"


@pytest.fixture(scope="module")
def mean_all():
    return load_body(DATA / "bodies" / "mean_all.obj")


@pytest.fixture(scope="module")
def mean_surface(mean_all):
    return Surface(mean_all.mesh)


def test_long_axis_stroke_runs_down_the_middle_of_a_tall_piece_inside_it():
    piece = Piece("p", np.array([[0.0, 0.0], [20.0, 0.0], [20.0, 60.0], [0.0, 60.0]]))
    pts = candidate_strokes(piece, SuggestParams(trim=0.1, margin_cm=2.0))[0]  # the long axis, through the centre
    assert np.allclose(pts[:, 0], 10.0, atol=0.3)  # through the centroid
    assert pts[0, 1] > pts[-1, 1]  # drawn downwards
    assert 2.0 <= pts[:, 1].min() and pts[:, 1].max() <= 58.0  # off the edges
    assert 40.0 < pts[0, 1] - pts[-1, 1] < 56.0


@pytest.mark.parametrize("settle", [False, True])
def test_suggested_shirt_strokes_lie_on_their_pieces_and_the_body_with_matched_lengths(mean_all, mean_surface, settle):
    pattern = load_pattern(SHIRT)
    strokes = suggest_strokes(mean_all, pattern, params=SuggestParams(settle=settle), surface=mean_surface)
    pieces = [p.pattern.piece for p in strokes.pairs]
    # Every big piece (torso halves and sleeve halves) gets one; the drawing order is largest first.
    assert sorted(pieces) == sorted(p.name for p in pattern.pieces)
    check_strokes(strokes, pattern)  # in GarmentCode's panel coordinates, on the pieces
    resolved = resolve_strokes(strokes, pattern, mean_surface)
    for pair in resolved.pairs:
        assert pair.body.surface.distance.max() < 0.005  # drawn on the surface
        lb = float(arc_length(pair.body.surface_points)[-1])
        assert lb / (pair.pattern.length_cm / 100) == pytest.approx(1.0, abs=0.12 if settle else 0.03)
    # A sleeve's stroke lies on its arm, not on the torso: the body point's |x| is past the shoulder.
    for pair in strokes.pairs:
        if "sleeve" in pair.pattern.piece:
            assert np.abs(pair.body.points[:, 0]).min() > 0.2
    assert strokes.meta["settled"] is settle


def test_suggest_needs_a_placement_and_a_body_it_was_made_for(mean_all, mean_surface):
    pattern = load_pattern(SHIRT)
    for piece in pattern.pieces:
        piece.placement = None
    with pytest.raises(InputError, match="carries no placement"):
        suggest_strokes(mean_all, pattern, surface=mean_surface)
    far = load_pattern(SHIRT)
    for piece in far.pieces:
        piece.placement.translation = piece.placement.translation + [5.0, 0.0, 0.0]
    with pytest.raises(InputError, match="reaches the body"):
        suggest_strokes(mean_all, far, surface=mean_surface)


def test_suggest_for_a_kimono_from_the_generator(body, body_surface):
    """The kimono generator hangs its pieces as on a kimono stand around the default body."""
    kimono = make_kimono()
    strokes = suggest_strokes(body, kimono, params=SuggestParams(settle=False), surface=body_surface)
    assert len(strokes) >= 4
    check_strokes(strokes, kimono)


def test_scale_polyline_keeps_the_middle_and_continues_straight():
    line = np.c_[np.linspace(0, 1, 11), np.zeros(11), np.zeros(11)]
    short = scale_polyline(line, 0.5)
    np.testing.assert_allclose(short[[0, -1], 0], [0.25, 0.75])
    long = scale_polyline(line, 1.4)
    np.testing.assert_allclose(long[[0, -1], 0], [-0.2, 1.2])
    assert len(long) == 11


def test_perturbation_changes_length_place_and_direction_and_drops_one(mean_surface):
    strokes = read_strokes(DATA.parent.parent / "src" / "kitsuke" / "assets" / "strokes" / "shirt_mean_all.json")
    shaky = perturb_strokes(strokes, mean_surface, np.random.default_rng(3))
    assert len(shaky) == len(strokes) - 1
    notes = shaky.meta["perturbed"]["strokes"]
    assert all(0.7 <= n["length"] <= 1.3 and n["shift_m"] <= 0.02 for n in notes)
    by_id = {p.id: p for p in strokes.pairs}
    for pair, note in zip(shaky.pairs, notes, strict=True):
        before = by_id[pair.id].body.points
        after = pair.body.points
        ratio = arc_length(after)[-1] / arc_length(before)[-1]
        assert ratio == pytest.approx(note["length"], rel=0.08)  # lengths measured on the body surface
        first = after[-1] if note["backwards"] else after[0]
        assert np.linalg.norm(first - before[0]) < 0.02 + (1 - min(note["length"], 1)) * arc_length(before)[-1]
    # The same generator seed gives the same strokes; no perturbation at all gives the strokes back.
    again = perturb_strokes(strokes, mean_surface, np.random.default_rng(3))
    assert all(np.array_equal(a.body.points, b.body.points) for a, b in zip(shaky.pairs, again.pairs, strict=True))
    still = HandPerturbation(length=(1.0, 1.0), shift_m=0.0, backwards=0.0, drop_one=False)
    same = perturb_strokes(strokes, mean_surface, np.random.default_rng(0), still)
    for a, b in zip(strokes.pairs, same.pairs, strict=True):
        np.testing.assert_allclose(a.body.points, b.body.points, atol=2e-3)  # projected back on the surface
