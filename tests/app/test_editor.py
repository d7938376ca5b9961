"""The pattern editor's point and edge operations (no browser): each keeps the cloth's shape where it should,
renumbers seams and curves with the outline, says what it removed, and undoes."""

from __future__ import annotations

import numpy as np
import pytest

from kitsuke.app.editor import PatternEditor
from kitsuke.errors import InputError
from kitsuke.pattern import Pattern
from kitsuke.pattern._types import Curve, EdgeRef


def _two_panels() -> PatternEditor:
    ed = PatternEditor(Pattern("p"))
    ed.add_piece([[0, 0], [50, 0], [50, 60], [0, 60]], name="front")
    ed.add_piece([[0, 0], [50, 0], [50, 60], [0, 60]], name="back")
    ed.sew(EdgeRef("front", 1), EdgeRef("back", 3))
    ed.sew(EdgeRef("front", 3), EdgeRef("back", 1))
    return ed


def _distance_to(polyline: np.ndarray, pts: np.ndarray) -> np.ndarray:
    """Distance of each point (m, 2) to a polyline (k, 2)."""
    a, b = polyline[:-1], polyline[1:]
    ab = b - a
    d = pts[:, None, :] - a[None]
    t = np.clip(np.einsum("mkj,kj->mk", d, ab) / np.einsum("kj,kj->k", ab, ab), 0, 1)
    return np.min(np.linalg.norm(d - t[..., None] * ab, axis=2), axis=1)


@pytest.mark.parametrize(
    "curve",
    [
        None,
        Curve("quadratic", [[0.4, 0.3]]),
        Curve("cubic", [[0.2, -0.25], [0.7, 0.35]]),
        Curve("circle", [[0.5, 0.2]]),
    ],
    ids=["straight", "quadratic", "cubic", "circle"],
)
def test_insert_point_keeps_the_edge_shape(curve):
    ed = PatternEditor(Pattern("p"))
    ed.add_piece([[0, 0], [50, 0], [50, 60], [0, 60]], name="a")
    p = ed.pattern.copy()
    if curve is not None:
        p.pieces[0].curves = {2: curve}  # the top edge, (50, 60) -> (0, 60)
    ed = PatternEditor(p)
    before = ed.pattern.piece("a")
    old = before.sample_edge(2, tol_cm=0.005)
    at = before.edge_points(2, np.array([0.3]))[0] + [0.5, 0.5]  # a click beside the curve
    ed.insert_point("a", 2, at)
    after = ed.pattern.piece("a")
    assert after.n_edges == 5
    assert np.linalg.norm(after.outline[3] - before.edge_points(2, np.array([0.3]))[0]) < 0.71  # the nearest
    halves = np.vstack([after.sample_edge(2, tol_cm=0.005), after.sample_edge(3, tol_cm=0.005)])
    assert _distance_to(old, halves).max() < 0.02  # the same curve, cm
    assert after.edge_length(2) + after.edge_length(3) == pytest.approx(before.edge_length(2), rel=1e-3)
    assert after.area == pytest.approx(before.area, rel=1e-4)
    ed.undo()
    assert ed.pattern.piece("a") == before


def test_insert_and_delete_points_renumber_seams_and_say_what_they_removed():
    ed = _two_panels()
    lengths = {(s.a, s.b): ed.pattern.edge_length(s.a) for s in ed.pattern.seams}
    assert ed.insert_point("front", 0, [20, 0]) is None  # the hem: no seam on it
    seams = ed.pattern.seams
    assert {(s.a, s.b) for s in seams} == {(EdgeRef("front", 2), EdgeRef("back", 3)),
                                           (EdgeRef("front", 4), EdgeRef("back", 1))}  # fmt: skip
    for s in seams:  # still the same sides of the cloth
        assert ed.pattern.edge_length(s.a) == pytest.approx(60.0)
    assert sorted(lengths.values()) == [60.0, 60.0]
    warning = ed.insert_point("front", 2, [50, 30])  # the sewn right side
    assert warning is not None and "front:2" in warning and "removed" in warning
    assert len(ed.pattern.seams) == 1
    ed.undo()
    warning = ed.delete_point("front", 1)  # the corner (20, 0) inserted above: merges two unsewn edges
    assert warning is None and ed.pattern.piece("front").n_edges == 4
    assert {(s.a, s.b) for s in ed.pattern.seams} == {(EdgeRef("front", 1), EdgeRef("back", 3)),
                                                      (EdgeRef("front", 3), EdgeRef("back", 1))}  # fmt: skip
    warning = ed.delete_point("front", 0)  # merges edges 3 (sewn) and 0
    assert warning is not None and "front:3" in warning
    assert ed.pattern.piece("front").n_edges == 3
    with pytest.raises(InputError, match="fewest"):
        ed.delete_point("front", 0)
    with pytest.raises(InputError, match="corner already"):
        ed.insert_point("back", 0, [0.1, 0])


def test_delete_point_renumbers_curves():
    ed = PatternEditor(Pattern("p"))
    ed.add_piece([[0, 0], [50, 0], [50, 60], [25, 70], [0, 60]], name="a")
    ed.curve_edge("a", 3, [10, 70])
    curve = ed.pattern.piece("a").curves[3]
    ed.delete_point("a", 1)  # edges 0 and 1 merge; edge 3 becomes edge 2
    assert ed.pattern.piece("a").curves == {2: curve}


@pytest.mark.parametrize("kind", [None, "quadratic", "cubic", "circle"])
def test_curve_edge_puts_the_middle_where_the_handle_is(kind):
    ed = PatternEditor(Pattern("p"))
    ed.add_piece([[0, 0], [50, 0], [50, 60], [0, 60]], name="a")
    if kind is not None:
        p = ed.pattern.copy()
        ctrl = {"quadratic": [[0.5, 0.1]], "cubic": [[0.3, 0.1], [0.7, 0.1]], "circle": [[0.5, 0.1]]}[kind]
        p.pieces[0].curves = {2: Curve(kind, ctrl)}
        ed = PatternEditor(p)
    ed.curve_edge("a", 2, [28, 72])
    piece = ed.pattern.piece("a")
    assert piece.curves[2].type == (kind or "quadratic")
    target = [28, 72] if kind != "circle" else [25, 72]  # an arc's middle stays on the chord's bisector
    np.testing.assert_allclose(piece.edge_points(2, np.array([0.5]))[0], target, atol=1e-9)
    ed.curve_edge("a", 2, [25, 60.2])  # back onto the chord: straight again
    assert 2 not in ed.pattern.piece("a").curves


def test_move_point_warns_about_seams_and_validation_names_the_crossing_edges():
    ed = _two_panels()
    assert ed.move_point("front", 2, [50, 60.8]) is None  # the sewn side 60 -> 60.8 cm: within 2 %
    warning = ed.move_point("front", 2, [50, 66])
    assert warning is not None and "differ in length" in warning
    ed.move_point("front", 2, [-10, 30])  # pulled across the piece: the outline crosses itself
    errors = [i for i in ed.issues() if i.severity == "error"]
    assert len(errors) == 1 and errors[0].piece == "front" and errors[0].code == "self-intersection"
    assert len(errors[0].edges) == 2
    ed.undo()
    assert [i for i in ed.issues() if i.severity == "error"] == []


def test_reverse_seam_turns_it_round():
    ed = _two_panels()
    r = ed.pattern.seams[0].reversed
    ed.reverse_seam(EdgeRef("back", 3))
    assert ed.pattern.seams[0].reversed is (not r)
    ed.undo()
    assert ed.pattern.seams[0].reversed is r
    with pytest.raises(InputError, match="not sewn"):
        ed.reverse_seam(EdgeRef("front", 0))
