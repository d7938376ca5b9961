"""kitsuke strokes v1 files: round trip and every kind of malformed file (InputError naming file and
stroke)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from kitsuke.dressing import (
    BodyStroke,
    PatternStroke,
    StrokePair,
    Strokes,
    read_strokes,
    strokes_to_dict,
    write_strokes,
)
from kitsuke.errors import InputError


def sample_dict() -> dict:
    return {
        "format": "kitsuke.strokes",
        "version": 1,
        "pairs": [
            {
                "id": 1,
                "pattern": {"piece": "migoro_left", "points": [[5.0, 120.0], [5.0, 140.0], [6.0, 150.0]]},
                "body": {"points": [[0.07, 1.30, 0.11], [0.07, 1.10, 0.12]]},
            },
            {
                "id": 7,
                "pattern": {"piece": "migoro_left", "points": [[5.0, 170.0], [5.0, 190.0]]},
                "body": {"laser": {"rays": [[0.07, 1.3, 1.0, 0, 0, -1], [0.07, 1.2, 1.0, 0, 0, -2]], "hit": "last"}},
            },
        ],
    }


def write(tmp_path, obj, name="s.json"):
    p = tmp_path / name
    p.write_text(obj if isinstance(obj, str) else json.dumps(obj))
    return p


def test_read_gives_typed_strokes(tmp_path):
    s = read_strokes(write(tmp_path, sample_dict()))
    assert s.target == "body" and s.ids == [1, 7] and s.source.endswith("s.json")
    p1, p7 = s.pair(1), s.pair(7)
    assert p1.pattern.piece == "migoro_left" and p1.pattern.points.shape == (3, 2)
    assert p1.pattern.points.dtype == np.float64
    assert p1.body.points.shape == (2, 3) and not p1.body.is_laser and not p1.body.resolved
    assert p7.body.is_laser and p7.body.hit == "last" and p7.body.rays.shape == (2, 6) and p7.body.n_points == 2
    assert p1.pattern.length_cm == pytest.approx(20.0 + math.hypot(1.0, 10.0))
    with pytest.raises(KeyError):
        s.pair(3)


def test_round_trip_is_exact(tmp_path):
    d = sample_dict()
    d["target"] = "garment"
    d["meta"] = {"note": "re-wrap the left sleeve"}
    src = read_strokes(write(tmp_path, d))
    out = tmp_path / "out.json"
    write_strokes(src, out)
    back = read_strokes(out)
    assert strokes_to_dict(back) == strokes_to_dict(src)
    assert back.target == "garment" and back.meta == {"note": "re-wrap the left sleeve"}
    for a, b in zip(src.pairs, back.pairs):
        np.testing.assert_array_equal(a.pattern.points, b.pattern.points)
    # One point per line: the file stays readable and hand-editable.
    assert "[5.0, 120.0]," in out.read_text()
    assert list(tmp_path.glob(".*tmp")) == []  # atomic write left no temporary file


def test_built_in_python_and_written(tmp_path):
    s = Strokes(
        [
            StrokePair(3, PatternStroke("a", [[0, 0], [1, 1]]), BodyStroke(points=[[0, 1, 0], [0, 1.1, 0]])),
            StrokePair(
                4,
                PatternStroke("a", [[0, 0], [0, 2]]),
                BodyStroke(rays=[[0] * 3 + [1, 0, 0]] * 2, hit="first"),
            ),
        ]
    )
    write_strokes(s, tmp_path / "x.json")
    assert read_strokes(tmp_path / "x.json").ids == [3, 4]


def _set(d, path, value):
    obj = d
    for k in path[:-1]:
        obj = obj[k]
    if value is _DELETE:
        del obj[path[-1]]
    else:
        obj[path[-1]] = value


_DELETE = object()

BAD = [
    ("wrong format", ("format",), "kitsuke.pattern", r"not a kitsuke strokes file"),
    ("wrong version", ("version",), 2, r"unsupported kitsuke.strokes version 2"),
    ("bad target", ("target",), "shirt", r"target must be 'body' or 'garment'"),
    ("pairs not a list", ("pairs",), {}, r"'pairs' must be a list"),
    ("id missing", ("pairs", 0, "id"), _DELETE, r"pairs\[0\]: missing field 'id'"),
    ("id not int", ("pairs", 0, "id"), "one", r"pairs\[0\]: id must be an integer"),
    ("no body stroke", ("pairs", 0, "body"), _DELETE, r"stroke 1: has a pattern stroke but no body stroke"),
    (
        "no pattern stroke",
        ("pairs", 1, "pattern"),
        _DELETE,
        r"stroke 7: has a body stroke but no pattern stroke",
    ),
    (
        "one pattern point",
        ("pairs", 0, "pattern", "points"),
        [[1.0, 2.0]],
        r"stroke 1: .*at least 2 points, got 1",
    ),
    ("one body point", ("pairs", 0, "body", "points"), [[0, 1, 0]], r"stroke 1: .*at least 2 points, got 1"),
    (
        "one ray",
        ("pairs", 1, "body", "laser", "rays"),
        [[0, 1, 1, 0, 0, -1]],
        r"stroke 7: .*at least 2 points",
    ),
    (
        "NaN in pattern",
        ("pairs", 0, "pattern", "points", 1),
        [float("nan"), 1.0],
        r"stroke 1: .*point 1 .*NaN",
    ),
    (
        "inf in body",
        ("pairs", 0, "body", "points", 0),
        [0, float("inf"), 0],
        r"stroke 1: .*point 0 .*NaN or inf",
    ),
    ("2D body point", ("pairs", 0, "body", "points"), [[0, 1], [0, 2]], r"stroke 1: .*shape \(n, 3\)"),
    ("string point", ("pairs", 0, "pattern", "points"), [["a", 1], [2, 3]], r"stroke 1: .*numbers"),
    ("piece not a name", ("pairs", 0, "pattern", "piece"), 3, r"stroke 1: .*piece must be a non-empty"),
    ("zero-length", ("pairs", 0, "pattern", "points"), [[1, 1], [1, 1]], r"stroke 1: .*zero length"),
    (
        "bad hit",
        ("pairs", 1, "body", "laser", "hit"),
        "middle",
        r"stroke 7: laser hit must be 'first' or 'last'",
    ),
    (
        "zero ray",
        ("pairs", 1, "body", "laser", "rays", 1),
        [0, 1, 1, 0, 0, 0],
        r"stroke 7: laser ray 1 .*zero",
    ),
    ("no rays", ("pairs", 1, "body", "laser", "rays"), _DELETE, r"stroke 7: laser stroke needs 'rays'"),
    (
        "both forms",
        ("pairs", 0, "body", "laser"),
        {"rays": [], "hit": "first"},
        r"stroke 1: .*exactly one of",
    ),
]


@pytest.mark.parametrize(("why", "path", "value", "match"), BAD, ids=[b[0] for b in BAD])
def test_bad_files_name_the_file_and_the_stroke(tmp_path, why, path, value, match):
    d = sample_dict()
    _set(d, path, value)
    # json.dumps writes NaN / Infinity tokens, which Python's reader accepts: the check must catch them.
    p = write(tmp_path, json.dumps(d))
    with pytest.raises(InputError, match=match) as e:
        read_strokes(p)
    assert e.value.path == str(p) and str(e.value).startswith(str(p))


def test_duplicate_ids(tmp_path):
    d = sample_dict()
    d["pairs"][1]["id"] = 1
    with pytest.raises(InputError, match=r"stroke id 1 is used twice \(pairs 0 and 1\)"):
        read_strokes(write(tmp_path, d))


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ("{not json", r"invalid JSON at line 1"),
        ("[1, 2]", r"top level is a list"),
        ("", r"strokes file is empty"),
    ],
)
def test_unreadable_files(tmp_path, text, match):
    p = write(tmp_path, text)
    with pytest.raises(InputError, match=match) as e:
        read_strokes(p)
    assert e.value.path == str(p)


def test_missing_file(tmp_path):
    with pytest.raises(InputError, match="strokes file not found"):
        read_strokes(tmp_path / "nope.json")
