"""Cloth layers of a pattern (`meta["layers"]`): the kimono's left front over its right, parsing, bad input."""

from __future__ import annotations

import json

import numpy as np
import pytest

from kitsuke.errors import InputError
from kitsuke.pattern import (
    LayerRegion,
    Pattern,
    Piece,
    face_layers,
    load_pattern,
    mesh_pattern,
    pattern_layers,
    save_pattern,
    validate,
)


def test_kimono_left_front_over_right(kimono):
    """The left okumi, the left body panel's front half and the collar's left crossing lie on layer 2, their
    right counterparts on layer 1; the backs, the sleeves and the collar round the neck on none."""
    regions = pattern_layers(kimono.meta, kimono.piece_names)
    assert {(r.piece, r.layer) for r in regions} == {(p, 2) for p in ("okumi_left", "migoro_left", "eri")} | {
        (p, 1) for p in ("okumi_right", "migoro_right", "eri")
    }
    pm = mesh_pattern(kimono, edge_length=3.0)
    assert pm.layers == regions
    corners = pm.vertices_cm[pm.faces]
    layer = face_layers(pm.layers, pm.piece_names, pm.piece_faces, corners)
    length = kimono.meta["kimono"]["size"]["length"]
    for k, name in enumerate(pm.piece_names):
        a, b = pm.piece_faces[k]
        mine, y = layer[a:b], corners[a:b, :, 1].mean(axis=1)
        if name.startswith("okumi"):
            assert (mine == (2 if name.endswith("left") else 1)).all()
        elif name.startswith("migoro"):
            want = 2 if name.endswith("left") else 1
            assert (mine[y < length - 1] == want).all() and (mine[y > length + 1] == 0).all()
        elif name.startswith("sode"):
            assert not mine.any()
        else:  # the collar: its left end on 2, its right end on 1, round the neck on none
            ends = y < 20, y > y.max() - 20
            assert (mine[ends[0]] == 2).all() and (mine[ends[1]] == 1).all() and (mine == 0).sum() > 10


def test_layers_survive_the_pattern_json(kimono, tmp_path):
    path = tmp_path / "kimono.json"
    save_pattern(kimono, path)
    back = load_pattern(path)
    assert pattern_layers(back.meta, back.piece_names) == pattern_layers(kimono.meta, kimono.piece_names)


def test_no_layers():
    assert pattern_layers({}, ["a"]) == ()
    assert face_layers((), ["a"], np.array([[0, 2]]), np.zeros((2, 3, 2))) is None


@pytest.mark.parametrize(
    "layers, text",
    [
        ({"piece": "a"}, "not a list"),
        ([{"piece": "nope", "layer": 1}], "no piece named 'nope'"),
        ([{"piece": "a"}], 'needs "piece"'),
        ([{"piece": "a", "layer": 0}], "layer must be an integer 1..62"),
        ([{"piece": "a", "layer": 63}], "layer must be an integer 1..62"),
        ([{"piece": "a", "layer": True}], "layer must be an integer"),
        ([{"piece": "a", "layer": 1, "box_cm": [0, 0, 1]}], "box_cm must be"),
        ([{"piece": "a", "layer": 1, "box_cm": [5, 0, 1, 1]}], "box_cm must be"),
        ([{"piece": "a", "layer": 1, "box_cm": [0, 0, 1, float("nan")]}], "box_cm must be"),
    ],
    ids=["not-list", "unknown-piece", "no-layer", "zero", "too-high", "bool", "short-box", "empty-box", "nan-box"],
)
def test_bad_layers(layers, text, tmp_path):
    """Malformed layers: an error from validate, and a one-line InputError naming the file when loading."""
    if text == "not a list":
        text = "must be a list"
    with pytest.raises(InputError, match=text):
        pattern_layers({"layers": layers}, ["a"])
    square = Piece("a", np.array([[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]]))
    assert [i.code for i in validate(Pattern("p", [square], [], {"layers": layers}))] == ["bad-layers"]
    d = {
        "format": "kitsuke.pattern",
        "version": 1,
        "name": "p",
        "pieces": [{"name": "a", "outline": [[0, 0], [10, 0], [10, 10], [0, 10]]}],
        "seams": [],
        "meta": {"layers": layers},
    }
    path = tmp_path / "p.json"
    path.write_text(json.dumps(d, allow_nan=True))
    with pytest.raises(InputError, match="p.json") as e:
        load_pattern(path)
    assert "\n" not in str(e.value)


def test_box_selects_faces_by_centroid():
    regions = (LayerRegion("a", 1), LayerRegion("b", 4, (0.0, 0.0, 1.0, 1.0)))
    corners = np.array([[[0, 0], [1, 0], [0, 1]], [[5, 5], [6, 5], [5, 6]], [[0, 0], [1, 0], [0, 1]]], float)
    layer = face_layers(regions, ["a", "b"], np.array([[0, 1], [1, 3]]), corners)
    assert layer.tolist() == [1, 0, 4]
