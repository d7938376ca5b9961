"""GarmentCode specification import: counts, lengths, orientation, placement, stitch directions, bad files."""

from __future__ import annotations

import copy
import json

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from kitsuke.errors import InputError
from kitsuke.pattern import decide_reversed, garmentcode_from_dict, load_pattern, validate

from .conftest import HOODY, SHIRT


def raw(path):
    return json.loads(path.read_text())


@pytest.mark.parametrize(("name", "pieces", "seams"), [("shirt", 8, 18), ("hoody", 6, 12)])
def test_counts_and_stitched_lengths(request, name, pieces, seams):
    pattern = request.getfixturevalue(name)
    assert (len(pattern.pieces), len(pattern.seams)) == (pieces, seams)
    for s in pattern.seams:
        la, lb = pattern.edge_length(s.a), pattern.edge_length(s.b)
        assert abs(la - lb) <= 0.01 * max(la, lb), (s, la, lb)
    assert validate(pattern) == []


@pytest.mark.parametrize("path", [SHIRT, HOODY])
def test_outlines_ccw_and_3d_positions_kept(path):
    pattern = load_pattern(path)
    spec = raw(path)["pattern"]["panels"]
    for piece in pattern.pieces:
        assert piece.signed_area > 0
        panel = spec[piece.name]
        verts = np.array(panel["vertices"], dtype=float)
        # GarmentCode's own placement of its vertices (edges are already an ordered loop in these files).
        rot = Rotation.from_euler("xyz", panel["rotation"], degrees=True).as_matrix()
        expected = (np.c_[verts, np.zeros(len(verts))] @ rot.T + panel["translation"]) / 100.0
        np.testing.assert_allclose(piece.placement.apply(piece.outline), expected, atol=1e-9)
        # The outer face (local +Z) looks away from the body's vertical axis.
        centre = piece.placement.apply(piece.polygon()).mean(axis=0)
        assert piece.placement.normal[[0, 2]] @ centre[[0, 2]] > 0, piece.name


def _same_piece_corners_merged(pattern) -> list:
    """Join the seam ends that meet; return groups holding two different corners of one piece (a flipped seam)."""
    parent: dict = {}

    def find(x):
        parent.setdefault(x, x)
        while parent[x] != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x

    for s in pattern.seams:
        na, nb = (pattern.piece(r.piece).n_edges for r in (s.a, s.b))
        a0, a1 = (s.a.piece, s.a.edge), (s.a.piece, (s.a.edge + 1) % na)
        b0, b1 = (s.b.piece, s.b.edge), (s.b.piece, (s.b.edge + 1) % nb)
        for x, y in ((a0, b1), (a1, b0)) if s.reversed else ((a0, b0), (a1, b1)):
            parent[find(x)] = find(y)
    groups: dict = {}
    for corner in list(parent):
        groups.setdefault(find(corner), []).append(corner)
    return [g for g in groups.values() if len({p for p, _ in g}) < len(g)]


@pytest.mark.parametrize("name", ["shirt", "hoody"])
def test_stitch_directions_are_consistent(request, name):
    pattern = request.getfixturevalue(name)
    assert all(s.reversed for s in pattern.seams)  # every piece faces outwards
    assert _same_piece_corners_merged(pattern) == []
    # The check would catch a flipped stitch: turn the first side seam around.
    broken = copy.copy(pattern)
    k = next(i for i, s in enumerate(pattern.seams) if "ftorso" in s.a.piece and "btorso" in s.b.piece)
    s = pattern.seams[k]
    broken.seams = [*pattern.seams[:k], type(s)(s.a, s.b, False), *pattern.seams[k + 1 :]]
    assert _same_piece_corners_merged(broken) != []


def test_placement_decides_clear_stitches_and_the_rule_the_rest(hoody, shirt):
    how = {}
    for name, pattern in (("shirt", shirt), ("hoody", hoody)):
        for i, s in enumerate(pattern.seams):
            rev, how[name, i] = decide_reversed(pattern.piece(s.a.piece), s.a.edge, pattern.piece(s.b.piece), s.b.edge)
            assert rev
    # Only the hood-to-back-neck stitches (hood at right angles to the back) need the orientation rule.
    assert sorted(k for k, v in how.items() if v == "orientation") == [("hoody", 1), ("hoody", 5)]
    assert sum(v == "distance" for v in how.values()) >= 18


def test_circle_edges_keep_their_radius(hoody):
    piece = hoody.piece("left_btorso")
    radius = raw(HOODY)["pattern"]["panels"]["left_btorso"]["edges"][1]["curvature"]["params"][0]
    p0, p1 = piece.edge_endpoints(1)
    mid = piece.edge_points(1, [0.5])[0]
    a, b, c = np.linalg.norm(p1 - p0), np.linalg.norm(mid - p0), np.linalg.norm(mid - p1)
    u, v = mid - p0, p1 - p0
    area = 0.5 * abs(u[0] * v[1] - u[1] * v[0])
    assert a * b * c / (4 * area) == pytest.approx(radius, rel=1e-9)  # circumradius
    # the back neckline curves into the panel (below its chord)
    assert mid[1] < 0.5 * (p0[1] + p1[1])


def test_edges_out_of_order_are_chained_and_stitches_renumbered():
    spec = raw(SHIRT)
    original = garmentcode_from_dict(copy.deepcopy(spec))
    panel = spec["pattern"]["panels"]["left_ftorso"]
    edges = panel["edges"]
    # List edges 2 and 3 the other way round, and edge 3 backwards (its curve must turn with it).
    e3 = edges[3]
    e3["endpoints"] = e3["endpoints"][::-1]
    e3["curvature"]["params"] = [[1 - x, -y] for x, y in e3["curvature"]["params"][::-1]]
    edges[2], edges[3] = edges[3], edges[2]
    for st in spec["pattern"]["stitches"]:
        for side in st:
            if side["panel"] == "left_ftorso" and side["edge"] in (2, 3):
                side["edge"] = 5 - side["edge"]
    shuffled = garmentcode_from_dict(spec)
    before, after = original.piece("left_ftorso"), shuffled.piece("left_ftorso")
    np.testing.assert_allclose(after.outline, before.outline)  # same loop, same start
    np.testing.assert_allclose(after.polygon(), before.polygon(), atol=1e-9)  # same curves
    assert shuffled.seams == original.seams  # stitches follow the renumbering
    assert shuffled.meta["import"]["edge_map"] == {
        "left_ftorso": {str(g): k for g, k in [(0, 0), (1, 1), (2, 3), (3, 2), (4, 4), (5, 5), (6, 6)]}
    }


def _mutated(mutate):
    spec = raw(SHIRT)
    mutate(spec)
    return spec


@pytest.mark.parametrize(
    ("mutate", "expected"),
    [
        (lambda d: d["pattern"]["panels"]["left_ftorso"]["edges"].pop(2), "do not form one closed loop"),
        (lambda d: d["pattern"]["stitches"][0][0].update(panel="cape"), "no panel named 'cape'"),
        (lambda d: d["pattern"]["stitches"][0][0].update(edge=40), "not 40"),
        (
            lambda d: d["pattern"]["panels"]["left_ftorso"]["edges"][2]["curvature"].update(type="nurbs"),
            "unsupported curvature type 'nurbs'",
        ),
        (lambda d: d["pattern"]["panels"]["left_ftorso"]["vertices"][1].__setitem__(0, float("nan")), "NaN"),
        (lambda d: d["pattern"]["panels"]["left_ftorso"]["vertices"].__setitem__(4, [35, 10]), "crosses itself"),
    ],
)
def test_bad_garmentcode_files(tmp_path, mutate, expected):
    path = tmp_path / "bad_specification.json"
    path.write_text(json.dumps(_mutated(mutate)))
    with pytest.raises(InputError) as err:
        load_pattern(path)
    assert err.value.path == str(path) and expected in err.value.message
