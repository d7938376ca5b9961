"""kitsuke pattern JSON v1: round trips, and every bad input named in the issue as an InputError naming the file."""

from __future__ import annotations

import json

import numpy as np
import pytest

from kitsuke.errors import InputError
from kitsuke.pattern import (
    Curve,
    EdgeRef,
    Pattern,
    Piece,
    Seam,
    load_pattern,
    load_pattern_with_issues,
    pattern_to_dict,
    save_pattern,
    validate,
)

from .conftest import two_squares


def write(tmp_path, obj, name="p.json") -> str:
    path = tmp_path / name
    path.write_text(obj if isinstance(obj, str) else json.dumps(obj))
    return str(path)


def test_round_trip_keeps_everything(tmp_path, shirt, kimono):
    for pattern in (shirt, kimono):
        out = tmp_path / f"{pattern.name}.json"
        save_pattern(pattern, out)
        again = load_pattern(out)
        assert again.pieces == pattern.pieces  # outlines, curves, flags and placements (with folds)
        assert again.seams == pattern.seams
        assert again.meta == json.loads(json.dumps(pattern.meta))
        assert pattern_to_dict(again) == pattern_to_dict(pattern)


def test_units_are_converted_to_cm(tmp_path):
    d = two_squares()
    d["units"] = "mm"
    p = load_pattern(write(tmp_path, d))
    assert p.piece("left").area == pytest.approx(1.0)  # 10 mm squares


def test_valid_pattern_has_no_issues(tmp_path):
    pattern, issues = load_pattern_with_issues(write(tmp_path, two_squares()))
    assert issues == [] and validate(pattern) == []
    assert pattern.seams == [Seam(EdgeRef("left", 1), EdgeRef("right", 3), True)]


def test_length_mismatch_is_a_warning_not_an_error(tmp_path):
    d = two_squares(b={"piece": "right", "edge": 0})  # the curved edge: longer than 10 cm by more than 1 %
    pattern, issues = load_pattern_with_issues(write(tmp_path, d))
    assert [i.code for i in issues] == ["length-mismatch"]
    assert issues[0].severity == "warning" and issues[0].seam == 0
    # within 1 % is fine: a 10.05 cm edge against a 10 cm one
    d = two_squares()
    d["pieces"][1]["outline"] = [[0, 0], [10, 0], [10, 10.05], [0, 10.05]]
    assert load_pattern_with_issues(write(tmp_path, d))[1] == []


def test_a_sliver_piece_is_a_warning(tmp_path):
    # GarmentCode's sampler made trouser cuffs 0.25 mm tall and 18.6 cm long; a 1 cm strip is fine.
    for height, codes in ((0.025, ["sliver"]), (1.0, [])):
        d = two_squares()
        d["pieces"].append({"name": "strip", "outline": [[0, 0], [18.6, 0], [18.6, height], [0, height]]})
        pattern, issues = load_pattern_with_issues(write(tmp_path, d))
        assert [i.code for i in issues] == codes
    assert issues == [] and pattern.piece("strip").area == pytest.approx(18.6)
    d["pieces"][-1]["outline"] = [[0, 0], [18.6, 0], [18.6, 0.025], [0, 0.025]]
    sliver = validate(load_pattern_with_issues(write(tmp_path, d))[0])[0]
    assert sliver.severity == "warning" and sliver.piece == "strip" and "0.25 mm wide" in sliver.message


def _broken(mutate):
    d = two_squares()
    mutate(d)
    return d


BAD = {
    "not JSON": ("{not json", "invalid JSON"),
    "wrong format": ({"format": "kitsuke.poses", "version": 1}, "format is 'kitsuke.poses'"),
    "wrong version": (_broken(lambda d: d.update(version=2)), "unsupported kitsuke.pattern version 2"),
    "missing pieces": (_broken(lambda d: d.pop("pieces")), "missing field 'pieces'"),
    "missing outline": (_broken(lambda d: d["pieces"][0].pop("outline")), "missing field 'outline'"),
    "NaN": (
        '{"format": "kitsuke.pattern", "version": 1, "pieces": [{"name": "a", "outline": [[0, 0], [NaN, 0], [1, 1]]}]}',
        "NaN or infinity",
    ),
    "infinity": (_broken(lambda d: d["pieces"][0]["outline"].__setitem__(1, [1e999, 0])), "NaN or infinity"),
    "string number": (_broken(lambda d: d["pieces"][0]["outline"].__setitem__(1, ["10", 0])), "expected a number"),
    "two points": (_broken(lambda d: d["pieces"][0].update(outline=[[0, 0], [1, 0]])), "at least 3"),
    "zero area": (_broken(lambda d: d["pieces"][0].update(outline=[[0, 0], [1, 0], [2, 0]])), "zero area"),
    "self-intersecting": (
        _broken(lambda d: d["pieces"][0].update(outline=[[0, 0], [10, 10], [10, 0], [0, 10]])),
        "crosses itself",
    ),
    "clockwise": (_broken(lambda d: d["pieces"][0].update(outline=[[0, 0], [0, 10], [10, 10], [10, 0]])), "clockwise"),
    "repeated point": (
        _broken(lambda d: d["pieces"][0].update(outline=[[0, 0], [10, 0], [10, 0], [0, 10]])),
        "zero length",
    ),
    "unknown piece": (_broken(lambda d: d["seams"][0]["b"].update(piece="sleeve")), "no piece named 'sleeve'"),
    "unknown edge": (_broken(lambda d: d["seams"][0]["b"].update(edge=4)), "has edges 0..3, not 4"),
    "duplicate names": (_broken(lambda d: d["pieces"][1].update(name="left")), "'left' is used 2 times"),
    "edge in two seams": (_broken(lambda d: d["seams"].append(dict(d["seams"][0]))), "already sewn"),
    "edge sewn to itself": (_broken(lambda d: d["seams"][0].update(b=d["seams"][0]["a"])), "to itself"),
    "bad curve": (_broken(lambda d: d["pieces"][1]["curves"]["0"].update(type="spline")), "unknown curve type"),
    "curve on missing edge": (
        _broken(lambda d: d["pieces"][1].update(curves={"9": {"type": "quadratic", "control": [[0.5, 0.1]]}})),
        "curve on edge 9",
    ),
    "bad placement": (
        _broken(lambda d: d["pieces"][0].update(placement={"translation": [0, 1]})),
        "placement.translation",
    ),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_input_names_the_file_and_the_problem(tmp_path, case):
    content, expected = BAD[case]
    path = write(tmp_path, content)
    with pytest.raises(InputError) as err:
        load_pattern(path)
    assert err.value.path == path
    assert expected in err.value.message
    assert "\n" not in str(err.value)


def test_validate_lists_all_problems_without_raising():
    square = [[0, 0], [10, 0], [10, 10], [0, 10]]
    pattern = Pattern(
        "p",
        [Piece("a", square), Piece("a", square), Piece("cw", square[::-1])],
        [Seam(EdgeRef("a", 0), EdgeRef("ghost", 0)), Seam(EdgeRef("a", 1), EdgeRef("cw", 7))],
    )
    codes = sorted(i.code for i in validate(pattern))
    assert codes == ["clockwise", "duplicate-name", "unknown-edge", "unknown-piece"]


def test_types_reject_malformed_data():
    with pytest.raises(InputError, match="needs 2 control points"):
        Curve("cubic", [[0.5, 0.1]])
    with pytest.raises(InputError, match="x = 0.5"):
        Curve("circle", [[0.3, 0.1]])
    with pytest.raises(InputError, match="shape"):
        Piece("p", np.zeros((4, 3)))
    piece = Piece("p", [[0, 0], [1, 0], [0, 1]], {"1": Curve("quadratic", [[0.5, 0.2]])})
    assert list(piece.curves) == [1]


def test_unknown_extension_and_missing_file(tmp_path):
    with pytest.raises(InputError, match="unknown pattern file type"):
        load_pattern(write(tmp_path, "x", "p.txt"))
    with pytest.raises(InputError, match="not found"):
        load_pattern(tmp_path / "nope.json")
    with pytest.raises(InputError, match="neither kitsuke"):
        load_pattern(write(tmp_path, {"hello": 1}))
