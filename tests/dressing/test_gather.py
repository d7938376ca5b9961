"""Gathered seams: a seam of unequal sides gathers the longer side in the cloth model's rest shape."""

from __future__ import annotations

import numpy as np
import pytest

from kitsuke.cloth import ClothModel
from kitsuke.dressing._gather import gathered_rest
from kitsuke.dressing._weld import weld
from kitsuke.pattern import Pattern, Piece, mesh_pattern
from kitsuke.pattern._types import EdgeRef, Seam


def _band_on_panel(band_cm: float, panel_cm: float) -> Pattern:
    """A 6 cm band whose lower edge (`band_cm` long) is sewn to the top of a 30 cm tall panel (`panel_cm` wide)."""
    band = Piece("band", np.array([[0.0, 0.0], [band_cm, 0.0], [band_cm, 6.0], [0.0, 6.0]]))
    panel = Piece("panel", np.array([[0.0, 0.0], [panel_cm, 0.0], [panel_cm, 30.0], [0.0, 30.0]]))
    seams = [Seam(EdgeRef("band", 0), EdgeRef("panel", 2))]
    return Pattern("gathered", [band, panel], seams)


def _model(pattern: Pattern, **settings):
    pm = mesh_pattern(pattern, edge_length=1.5)
    welded = weld(pm)
    rest, gathers = gathered_rest(pm, welded, **({"min_difference": 0.03, "min_cm": 1.0, "depth_cm": 8.0} | settings))
    return pm, welded, ClothModel.from_corners(welded.faces, rest, n_vertices=welded.n_vertices), gathers


def _seam_rest_length(pm, welded, model) -> float:
    """The model's rest length along the sewn seam, cm."""
    return _chain_rest_length(welded.vertex_of[pm.seam_vertices[0][:, 0]], model)


def _edge_rest_length(pm, welded, model, edge: EdgeRef) -> float:
    """The model's rest length along a piece's edge, cm."""
    return _chain_rest_length(welded.vertex_of[pm.edge_vertices[edge]], model)


def _chain_rest_length(chain, model) -> float:
    edges = {tuple(sorted(e)): i for i, e in enumerate(model.edges.tolist())}
    return 100.0 * sum(model.rest_lengths[edges[tuple(sorted(p))]] for p in zip(chain[:-1], chain[1:], strict=True))


def test_the_longer_side_is_gathered_onto_the_shorter():
    """A 30 cm band on a 20 cm panel: the seam's rest length is the panel's 20 cm (sewn as it is, it was the mean,
    25 cm: both sides strained 20-25 %), the band's far edge eases back towards its own length, and the panel,
    the shorter side, keeps its shape."""
    pattern = _band_on_panel(30.0, 20.0)
    pm, welded, model, gathers = _model(pattern)
    assert [(g.piece, round(g.ratio, 3)) for g in gathers] == [("band", pytest.approx(0.667, abs=1e-3))]
    assert _seam_rest_length(pm, welded, model) == pytest.approx(20.0, rel=0.02)
    plain = ClothModel.from_corners(welded.faces, welded.rest_corners, n_vertices=welded.n_vertices)
    assert _seam_rest_length(pm, welded, plain) == pytest.approx(25.0, rel=0.02)
    panel = slice(*welded.piece_faces[1])
    np.testing.assert_array_equal(model.rest_corners[panel], plain.rest_corners[panel])
    # the band's top edge, 6 cm from the seam: shortened less than the seam (smoothstep of 6/8: to 0.92 of it)
    assert 25.0 < _edge_rest_length(pm, welded, model, EdgeRef("band", 2)) < 29.5
    # every rest triangle keeps its area sign and a sensible shape
    assert (model.rest_areas > 0.2 * plain.rest_areas).all()


def test_nearly_equal_or_tiny_differences_are_not_gathered():
    """A difference under the share (2 % < 3 %) or under the centimetre (a rounding of the design) is shared
    between the sides as before; depth 0 gathers nothing."""
    for band, panel in ((20.4, 20.0), (5.9, 5.0)):
        _, welded, model, gathers = _model(_band_on_panel(band, panel))
        assert gathers == []
        np.testing.assert_array_equal(model.rest_corners, welded.rest_corners)
    _, welded, model, gathers = _model(_band_on_panel(30.0, 20.0), depth_cm=0.0)
    assert gathers == [] and np.array_equal(model.rest_corners, welded.rest_corners)


def test_validate_says_which_seams_dress_gathers(run_cli, tmp_path):
    """`kitsuke pattern validate` warns of every length mismatch and says which ones a wrap gathers (the same rule
    as the wrap's: over 3 % and 1 cm)."""
    from kitsuke.dressing._gather import gathered_seams
    from kitsuke.pattern import save_pattern

    gathered, rounded = _band_on_panel(30.0, 20.0), _band_on_panel(20.4, 20.0)
    assert gathered_seams(gathered, 0.03, 1.0) == [0] and gathered_seams(rounded, 0.03, 1.0) == []
    for pattern, says in ((gathered, True), (rounded, False)):
        path = tmp_path / f"{pattern.pieces[0].outline[1, 0]:g}.json"
        save_pattern(pattern, path)
        r = run_cli("pattern", "validate", path)
        assert r.code == 0 and "apart" in r.err
        assert ("its longer side is gathered" in r.err) == says


def test_a_garment_with_its_own_rest_shape_is_dragged_and_measured_at_it(body):
    """A GarmentFile whose rest shape is not its uv (gathered): the drag's model rests at it (from the uv it
    would pull the gathers open) and the strain map measures against it."""
    from kitsuke.dressing import DragSession
    from kitsuke.dressing.export import GarmentFile

    uv = np.array([[0.0, 0.0], [0.1, 0.0], [0.1, 0.1], [0.0, 0.1]])
    faces = np.array([[0, 1, 2], [0, 2, 3]])
    corner_uv = uv[faces]
    gathered = corner_uv * [0.7, 1.0]
    positions = np.c_[gathered[[0, 0, 0, 1], [0, 1, 2, 2]], np.zeros(4)] + [-0.035, 1.2, 0.3]
    file = GarmentFile(positions, faces, corner_uv, ["sheet"], np.array([[0, 2]]), rest_corners=gathered)
    session = DragSession(body, file)
    np.testing.assert_allclose(np.sort(session.model.rest_lengths), np.sort(
        ClothModel.from_corners(faces, gathered, n_vertices=4).rest_lengths))  # fmt: skip
    np.testing.assert_allclose(file.rest_edge_lengths[0, 0], 0.07)
    assert session.report().strain_max < 1e-9  # lying at its gathered rest: no strain


def test_gather_settings_refuse_negative_or_non_finite_values():
    from kitsuke.dressing.wrap import WrapParams
    from kitsuke.errors import InputError

    for name in ("gather.min_difference", "gather.min_cm", "gather.depth_cm"):
        for bad in (-1.0, float("nan"), float("inf")):
            with pytest.raises(InputError, match=name.split(".")[1]):
                WrapParams().changed({name: bad})
