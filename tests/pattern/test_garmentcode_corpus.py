"""GarmentCode designs other than the shipped shirt and hoody (tests/data/pattern/corpus, drawn by GarmentCode's
own programs): they import, sew into one garment surface, and strokes are read in GarmentCode's own panel
coordinates."""

from __future__ import annotations

import copy
import json

import numpy as np
import pytest

from kitsuke.dressing import check_sewable, in_file_frame, in_piece_frame
from kitsuke.dressing.strokes import BodyStroke, PatternStroke, StrokePair, Strokes, check_strokes
from kitsuke.errors import InputError
from kitsuke.pattern import decide_reversed, garmentcode_from_dict, load_pattern

from ..conftest import DATA

CORPUS = sorted((DATA / "pattern" / "corpus").glob("*_specification.json"))


@pytest.mark.parametrize("path", CORPUS, ids=lambda p: p.stem)
def test_every_corpus_design_imports_and_sews(path):
    pattern = load_pattern(path)
    pm = check_sewable(pattern)  # what `dress` meshes and sews
    assert pm.n_faces > 100
    # Every piece runs counter-clockwise seen from its outer face, curves included.
    assert all(p.signed_area > 0 for p in pattern.pieces)
    # Sewn outward-facing pieces meet with their edges running opposite ways.
    assert all(s.reversed for s in pattern.seams)


def test_a_circle_skirt_whose_corners_lie_on_one_line_is_read_by_its_arcs():
    """The back of a circle skirt: all four corners on y = 0, so only its arcs say which way it runs (GarmentCode
    draws it clockwise: it is mirrored like any back panel)."""
    spec = json.loads((DATA / "pattern" / "corpus" / "gc_s101_0003_specification.json").read_text())
    panel = {
        "translation": [0, 90, -12],
        "rotation": [0, 0, 0],
        "vertices": [[-0.4, 0], [26.4, 0], [101.1, 0], [-75.1, 0]],
        "edges": [
            {"endpoints": [0, 1], "curvature": {"type": "circle", "params": [13.42, 0, 1]}},
            {"endpoints": [1, 2]},
            {"endpoints": [2, 3], "curvature": {"type": "circle", "params": [88.19, 1, 0]}},
            {"endpoints": [3, 0]},
        ],
    }
    spec["pattern"]["panels"] = {"circle_back": panel}
    spec["pattern"]["stitches"] = []
    pattern = garmentcode_from_dict(spec)
    piece = pattern.piece("circle_back")
    assert piece.signed_area > 0 and "circle_back" in pattern.file_mirrored
    # The shoelace area of its corners alone is zero: the old test by corners read it either way.
    x, y = piece.outline[:, 0], piece.outline[:, 1]
    assert abs(float(x @ np.roll(y, -1) - np.roll(x, -1) @ y)) < 1e-9


def test_tiny_stitches_between_far_apart_panels_are_sewn_the_way_the_pieces_face():
    """Design 0012's 0.84 cm stitches between a sleeve and a bodice placed apart: their placement distances tie,
    and the placement alone paired them the wrong way round, which no sewing could repair."""
    pattern = load_pattern(DATA / "pattern" / "corpus" / "gc_s101_0012_specification.json")
    tiny = [s for s in pattern.seams if pattern.edge_length(s.a) < 1.0 and {s.a.piece, s.b.piece} & {"right_sleeve_b"}]
    assert tiny and all(s.reversed for s in tiny)
    rev, how = decide_reversed(
        pattern.piece(tiny[0].a.piece), tiny[0].a.edge, pattern.piece(tiny[0].b.piece), tiny[0].b.edge
    )
    assert rev and how == "placement disagrees"
    assert any("placement pairs its ends the other way" in n for n in pattern.meta["import"]["notes"])
    # Turned the other way, the pattern cannot be sewn: validation names the seam and the place.
    broken = copy.copy(pattern)
    k = pattern.seams.index(tiny[0])
    broken.seams = [*pattern.seams[:k], type(tiny[0])(tiny[0].a, tiny[0].b, False), *pattern.seams[k + 1 :]]
    with pytest.raises(InputError, match=r"seam \d+ \(.*edge \d+ - .*edge \d+\)"):
        check_sewable(broken)


def test_strokes_are_given_in_garmentcode_panel_coordinates():
    pattern = load_pattern(DATA / "pattern" / "shirt_mean_specification.json")
    back = "left_btorso"
    assert back in pattern.file_mirrored and "left_ftorso" not in pattern.file_mirrored
    raw = json.loads((DATA / "pattern" / "shirt_mean_specification.json").read_text())
    verts = np.array(raw["pattern"]["panels"][back]["vertices"], dtype=float)
    # A stroke between two of the panel's own vertices, as GarmentCode's file gives them, lies on the piece.
    pts = verts[[0, 2]] * 0.9 + verts[[2, 0]] * 0.1
    strokes = Strokes([StrokePair(1, PatternStroke(back, pts), BodyStroke(points=[[0, 1.3, -0.1], [0, 1.1, -0.1]]))])
    check_strokes(strokes, pattern)
    inside = in_piece_frame(strokes, pattern).pairs[0].pattern.points
    np.testing.assert_allclose(inside, pts * [-1.0, 1.0])
    np.testing.assert_allclose(in_file_frame(in_piece_frame(strokes, pattern), pattern).pairs[0].pattern.points, pts)
    # The same points taken as the piece's own coordinates leave the piece.
    with pytest.raises(InputError, match="outside piece"):
        check_strokes(in_piece_frame(strokes, pattern), pattern)


def test_pattern_validate_refuses_what_dress_would_naming_the_seam(run_cli, tmp_path):
    from kitsuke.pattern import save_pattern

    pattern = load_pattern(DATA / "pattern" / "corpus" / "gc_s101_0012_specification.json")
    k = next(i for i, s in enumerate(pattern.seams) if pattern.edge_length(s.a) < 1.0)
    s = pattern.seams[k]
    pattern.seams[k] = type(s)(s.a, s.b, False)
    path = tmp_path / "broken.json"
    save_pattern(pattern, path)
    r = run_cli("pattern", "validate", path)
    assert r.code == 2 and len(r.err.strip().splitlines()) == 1
    assert "broken.json" in r.err and f"seam {k} (" in r.err
    ok = run_cli("pattern", "validate", DATA / "pattern" / "corpus" / "gc_s101_0012_specification.json")
    assert ok.code == 0 and ": ok:" in ok.out
