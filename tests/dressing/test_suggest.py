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
from kitsuke.dressing._far_pieces import drawn_in_placements, seam_rise
from kitsuke.dressing._polyline import polygon_grid
from kitsuke.dressing.perturb import scale_polyline
from kitsuke.dressing.suggest import candidate_strokes
from kitsuke.errors import InputError
from kitsuke.geometry.surface import Surface
from kitsuke.pattern import Piece, load_pattern, make_kimono

from ..conftest import DATA

SHIRT = DATA / "pattern" / "shirt_mean_specification.json"
CORPUS = DATA / "pattern" / "corpus"


def _laid_out(pattern, names, out_m: float, down_m: float = 0.0):
    """`pattern` with pieces `names` moved `out_m` metres along their outer normal and `down_m` down: laid out
    far from the body as GarmentCode lays out a wide skirt's panels."""
    for name in names:
        pl = pattern.piece(name).placement
        pl.translation = pl.translation + out_m * pl.normal - [0.0, down_m, 0.0]
    return pattern


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


def test_a_skirt_laid_out_far_is_drawn_in_by_its_seams_to_the_waist_and_hips(mean_all, mean_surface):
    """A skirt laid 1.5 m out and 20 cm low (no normal reaches the body) is drawn in: raised until it meets the
    waistband it is sewn to, moved in until it touches the body, and stroked from the waist over the hips, each
    piece on its own side of the body."""
    skirt = ["skirt_front", "skirt_back"]
    pattern = _laid_out(load_pattern(CORPUS / "gc_s101_0003_specification.json"), skirt, 1.5, 0.2)
    moved = drawn_in_placements(pattern, skirt, mean_surface, SuggestParams().reach_m)
    assert set(moved) == set(skirt)
    anchors = {name: pattern.piece(name).placement for name in ("wb_front", "wb_back")}
    for name, (placement, touch_y) in moved.items():
        drawn = pattern.copy()
        drawn.piece(name).placement = placement
        assert abs(seam_rise(drawn, name, anchors)) < 0.005  # its waist seam is where the waistband's is
        assert 0.7 < touch_y < 1.05  # it touched the hips, not the feet
        placed = placement.apply(polygon_grid(drawn.piece(name).polygon(), 24))
        assert mean_surface.closest(placed).distance.min() < 0.02  # it touches the body
    strokes = suggest_strokes(mean_all, pattern, params=SuggestParams(settle=False), surface=mean_surface)
    check_strokes(strokes, pattern)
    by_piece = {p.pattern.piece: p.body.points for p in strokes.pairs}
    assert set(skirt) <= set(by_piece)
    assert (by_piece["skirt_front"][:, 2] > 0.03).all() and (by_piece["skirt_back"][:, 2] < -0.03).all()
    for name in skirt:
        pts = by_piece[name]
        assert mean_surface.closest(pts).distance.max() < 0.005
        assert 0.7 < pts[:, 1].min() and pts[:, 1].max() < 1.1  # waist to hips, not down the legs
        assert arc_length(pts)[-1] > 0.06


def test_a_far_piece_sewn_to_nothing_on_the_body_gets_no_stroke(mean_all, mean_surface):
    """The seams decide where a far piece goes: a skirt laid out far and sewn only to itself is left out (its
    waistband, the only piece near the body, is stroked instead)."""
    pattern = _laid_out(load_pattern(CORPUS / "gc_s101_0003_specification.json"), ["skirt_front", "skirt_back"], 1.5)
    pattern.seams = [s for s in pattern.seams if not {s.a.piece, s.b.piece} & {"wb_front", "wb_back"}]
    strokes = suggest_strokes(mean_all, pattern, params=SuggestParams(settle=False), surface=mean_surface)
    assert {p.pattern.piece for p in strokes.pairs} <= {"wb_front", "wb_back"}


def test_when_no_large_piece_reaches_the_body_the_smaller_ones_get_strokes(mean_all, mean_surface):
    """A dress whose skirt is laid out far (each skirt piece over twice a bodice piece): the bodice pieces, below
    the share rule (here a half), get strokes, the share rule holding among the pieces that reach the body (the
    waistband, under half the largest bodice piece, gets none), and the skirt is drawn in below them."""
    skirt = ["skirt_front", "skirt_back"]
    pattern = _laid_out(load_pattern(CORPUS / "gc_s101_0009_specification.json"), skirt, 1.5)
    params = SuggestParams(settle=False, min_area_share=0.5, min_area_cm2=np.inf)
    strokes = suggest_strokes(mean_all, pattern, params=params, surface=mean_surface)
    check_strokes(strokes, pattern)
    by_piece = {p.pattern.piece: p.body.points for p in strokes.pairs}
    torso = {"right_btorso", "right_ftorso", "left_btorso", "left_ftorso"}
    assert torso <= set(by_piece) and not {"wb_front", "wb_back"} & set(by_piece)
    assert set(skirt) <= set(by_piece)
    assert max(by_piece[name][:, 1].max() for name in skirt) < min(by_piece[name][:, 1].min() for name in torso)


def test_a_bodice_beside_a_much_larger_skirt_gets_strokes_of_its_own(mean_all, mean_surface):
    """GarmentCode's circle skirts are ten times a bodice panel: by the share rule alone (here 0.9 of the largest
    piece, so that this dress's skirt, three times its bodice panels, stands for one) only the skirt is stroked and
    the bodice grows from it; pieces of at least `min_area_cm2` get strokes too (the waistbands, 191-214 cm², do
    not)."""
    pattern = load_pattern(CORPUS / "gc_s101_0009_specification.json")
    torso = {"right_btorso", "right_ftorso", "left_btorso", "left_ftorso"}
    shares_only = SuggestParams(settle=False, min_area_share=0.9, min_area_cm2=np.inf)
    alone = suggest_strokes(mean_all, pattern, params=shares_only, surface=mean_surface)
    assert {p.pattern.piece for p in alone.pairs} == {"skirt_back"}
    with_floor = SuggestParams(settle=False, min_area_share=0.9, min_area_cm2=700.0)
    strokes = suggest_strokes(mean_all, pattern, params=with_floor, surface=mean_surface)
    check_strokes(strokes, pattern)
    assert {p.pattern.piece for p in strokes.pairs} == {"skirt_back", "skirt_front"} | torso
    for pair in strokes.pairs:
        if pair.pattern.piece in torso:  # on the torso, above the waist
            assert pair.body.points[:, 1].min() > 0.95 and np.abs(pair.body.points[:, 0]).max() < 0.25


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
