"""Quality measures against hand-computed answers."""

from __future__ import annotations

import json

import numpy as np
import pytest

from kitsuke.cloth import grid_sheet, grid_tube
from kitsuke.errors import InputError
from kitsuke.geometry import TriMesh
from kitsuke.metrics import (
    QualityTargets,
    inverted_triangles,
    mesh_edges,
    penetration,
    quality_report,
    seam_gap,
    strain,
)


@pytest.fixture(scope="module")
def box() -> TriMesh:
    """A closed 20 x 20 x 20 cm box centred at the origin: distances to it are exact by hand."""
    import trimesh

    b = trimesh.creation.box(extents=(0.2, 0.2, 0.2))
    return TriMesh(np.asarray(b.vertices), np.asarray(b.faces))


def test_penetration_counts_and_depths(box):
    pts = np.array(
        [
            [0.0, 0.0, 0.3],  # outside
            [0.0, 0.0, 0.099],  # 1 mm inside: below the 2 mm threshold
            [0.0, 0.0, 0.095],  # 5 mm inside
            [0.05, 0.02, 0.0],  # 5 cm inside (nearest face x = 0.1)
            [0.0, 0.0, 0.1005],  # just outside
        ]
    )
    p = penetration(pts, box)
    assert p.count == 2
    assert p.deepest_mm == pytest.approx(50.0)
    np.testing.assert_allclose(p.depth_m, [0.0, 0.001, 0.005, 0.05, 0.0], atol=1e-12)
    assert penetration(pts, box, threshold_m=0.0).count == 3
    assert penetration(np.zeros((0, 3)), box).count == 0


def test_strain_by_hand():
    pos = np.array([[0.0, 0.0, 0.0], [1.1, 0.0, 0.0], [0.0, 0.9, 0.0]])
    edges = np.array([[0, 1], [0, 2], [1, 2]])
    rest = np.array([1.0, 1.0, np.hypot(1.1, 0.9)])
    s = strain(pos, edges, rest)
    np.testing.assert_allclose(s.per_edge, [0.1, 0.1, 0.0], atol=1e-12)
    assert s.mean == pytest.approx(0.2 / 3) and s.max == pytest.approx(0.1)
    assert s.stretched == pytest.approx(0.1) and s.compressed == pytest.approx(0.1)
    assert set(s.worst_edges[:2]) == {0, 1}
    with pytest.raises(InputError, match="rest_lengths"):
        strain(pos, edges, rest[:2])
    with pytest.raises(InputError, match="positive"):
        strain(pos, edges, np.array([1.0, 0.0, 1.0]))


def test_seam_gap_by_hand():
    pos = np.array([[0.0, 0, 0], [0.0, 0.001, 0], [0.0, 0.002, 0.0], [0.0, 0.0, 0.003], [0.0, 0.001, 0.0]])
    g = seam_gap(pos, [(np.array([0, 1]), np.array([3, 4])), (np.array([2]), np.array([2]))])
    assert g.per_seam_mm == pytest.approx([3.0, 0.0])
    assert g.max_mm == pytest.approx(3.0)
    assert seam_gap(pos, []).max_mm == 0.0
    with pytest.raises(InputError, match="seam 0"):
        seam_gap(pos, [(np.array([0, 1]), np.array([3]))])
    with pytest.raises(InputError, match="do not exist"):
        seam_gap(pos, [(np.array([0]), np.array([9]))])


def test_inverted_triangles_definition():
    uv, f = grid_sheet(6, 6, 0.01)
    flat = np.c_[uv, np.zeros(len(uv))]
    assert not inverted_triangles(flat, f).any()
    # A curved surface (a tube) is not inverted anywhere, seams included.
    faces, _, _ = grid_tube(10, 4, 0.01)
    i, j = np.arange(40) % 10, np.arange(40) // 10
    tube = np.c_[np.sin(2 * np.pi * i / 10), 0.3 * j, np.cos(2 * np.pi * i / 10)] * 0.05
    assert not inverted_triangles(tube, faces).any()
    # Fold a corner triangle back over its neighbour: that triangle, and only it, is inverted.
    counts = np.bincount(f.reshape(-1))
    v = int(np.flatnonzero(counts == 1)[0])
    t = int(np.flatnonzero((f == v).any(axis=1))[0])
    a, b = [k for k in f[t] if k != v]
    folded = flat.copy()
    e = (folded[b] - folded[a]) / np.linalg.norm(folded[b] - folded[a])
    foot = folded[a] + ((folded[v] - folded[a]) @ e) * e
    folded[v] = foot + 0.9 * (foot - folded[v]) + [0, 0, 0.001]
    inv = inverted_triangles(folded, f)
    assert np.flatnonzero(inv).tolist() == [t]
    # A mesh whose winding differs between two triangles is not inverted: neighbours are compared as wound.
    g = f.copy()
    g[t] = g[t, ::-1]
    assert not inverted_triangles(flat, g).any()
    # Collapsed (area below 1 % of rest): inverted when the rest areas are given.
    squashed = flat.copy()
    squashed[v] = foot
    rest_areas = np.full(len(f), 0.5e-4)
    assert inverted_triangles(squashed, f, rest_areas=rest_areas)[t]
    assert not inverted_triangles(squashed, f)[t]


def test_quality_report_pass_and_fail(box):
    uv, f = grid_sheet(5, 5, 0.01)
    edges = mesh_edges(f)
    rest = np.linalg.norm(uv[edges[:, 0]] - uv[edges[:, 1]], axis=1)
    outside = np.c_[uv - 0.02, np.full(len(uv), 0.105)]  # 5 mm in front of the box's +z face
    good = quality_report(outside, f, box, rest_lengths=rest)
    assert good.ok and good.failures() == []
    assert good.penetration_count == 0 and good.strain_max == pytest.approx(0.0, abs=1e-12)
    d = json.loads(json.dumps(good.to_dict()))
    assert d["ok"] is True and d["targets"]["max_strain"] == 0.05 and d["n_faces"] == len(f)

    bad = outside * [1.08, 1.0, 1.0]  # 8 % stretch along x
    bad[0, 2] = 0.09  # one vertex 1 cm inside
    r = quality_report(bad, f, box, rest_lengths=rest, seams=[(np.array([0]), np.array([24]))])
    assert not r.ok
    assert r.passed == {
        "penetration": False,
        "max_strain": False,
        "mean_strain": False,
        "seam_gap": False,
        "inverted": True,
    }
    assert r.penetration_count == 1 and r.penetration_deepest_mm == pytest.approx(10.0, abs=0.01)
    assert len(r.failures()) == 4 and "penetration" not in r.failures()[0]
    assert "inside the body" in r.failures()[0]
    lenient = quality_report(bad, f, box, rest_lengths=rest, targets=QualityTargets(max_strain=1.0, mean_strain=0.5))
    assert lenient.passed["max_strain"] and lenient.passed["mean_strain"]


def test_quality_report_says_where_the_worst_edge_and_the_first_fold_are(box):
    """With the pieces given, a failing report names the piece and the place of the worst edge and of the first
    inverted triangle; without them it says nothing of where."""
    uv, f = grid_sheet(5, 5, 0.01)
    edges = mesh_edges(f)
    rest = np.linalg.norm(uv[edges[:, 0]] - uv[edges[:, 1]], axis=1)
    pos = np.c_[uv - 0.02, np.full(len(uv), 0.105)]
    corner = len(uv) - 1  # the sheet's last corner; the second piece starts at the first triangle touching it
    split = int(np.flatnonzero((f == corner).any(axis=1)).min())
    assert 0 < split < len(f) - 1
    pieces = (["left", "right"], np.array([[0, split], [split, len(f)]]))
    pos[corner] += [0.0, 0.0, 0.02]  # a spike there: its edges stretched
    r = quality_report(pos, f, box, rest_lengths=rest, pieces=pieces)
    a, b = edges[r.strain_worst_edges[0]]
    mid = (pos[a] + pos[b]) / 2
    assert r.strain_worst_at == f"piece right at ({mid[0]:.3f}, {mid[1]:.3f}, {mid[2]:.3f}) m"
    assert any(line.endswith(f"(worst on {r.strain_worst_at})") for line in r.failures())
    folded = pos.copy()
    v = f[0, 0]  # fold the first triangle's corner back over its neighbours (first piece)
    folded[v] = folded[f[0]].mean(axis=0) + 0.6 * (folded[f[0]].mean(axis=0) - folded[v])
    r = quality_report(folded, f, box, rest_lengths=rest, pieces=pieces)
    assert r.inverted_count >= 1 and r.inverted_at.startswith("piece left at (")
    assert any("(first on piece left at" in line for line in r.failures())
    plain = quality_report(pos, f, box, rest_lengths=rest)
    assert plain.strain_worst_at is None and plain.inverted_at is None
    with pytest.raises(InputError, match="pieces"):
        quality_report(pos, f, box, rest_lengths=rest, pieces=(["left"], pieces[1]))
    assert all("worst on" not in line for line in plain.failures())


def test_quality_report_rejects_bad_input(box):
    uv, f = grid_sheet(3, 3, 0.01)
    pos = np.c_[uv, np.zeros(len(uv))]
    with pytest.raises(InputError, match="rest_lengths"):
        quality_report(pos, f, box, rest_lengths=np.ones(3))
    with pytest.raises(InputError, match="faces"):
        quality_report(pos, f + 100, box, rest_lengths=np.ones(16))
    with pytest.raises(InputError, match="positions"):
        quality_report(pos[:, :2], f, box, rest_lengths=np.ones(16))
    with pytest.raises(InputError, match="body"):
        penetration(pos, "body.obj")  # type: ignore[arg-type]


def test_wrong_side_mm_and_layer_crossing():
    """Two layered sheets, the upper (2) 3 mm under the lower (1) over their middle: its vertices there are 3 mm on
    the wrong side (and the lower sheet's as much on its wrong side of the upper one); moved 3 mm over, none is;
    vertices beside the other sheet's border, or without layers, count 0."""
    from kitsuke.cloth import grid_sheet
    from kitsuke.metrics import layer_crossing_mm, wrong_side_mm

    uv, f = grid_sheet(7, 7, 0.02)
    nv = len(uv)
    faces = np.concatenate([f, f + nv])
    layer = np.r_[np.ones(len(f)), np.full(len(f), 2)].astype(np.int8)
    lower = np.c_[uv, np.zeros(nv)]
    upper = np.c_[uv + [0.006, 0.004], np.full(nv, -0.003)]
    wrong = wrong_side_mm(np.concatenate([lower, upper]), faces, layer, 2, 1)
    inner = (uv[:, 0] > 0.02) & (uv[:, 0] < 0.1) & (uv[:, 1] > 0.02) & (uv[:, 1] < 0.1)
    np.testing.assert_allclose(wrong[inner], 3.0, atol=1e-9)
    assert layer_crossing_mm(np.concatenate([lower, upper]), faces, layer) == pytest.approx(3.0)
    assert (wrong[~inner & ((uv[:, 0] > 0.115) | (uv[:, 1] > 0.115))] == 0.0).all()  # beside the lower sheet
    upper[:, 2] = 0.003
    assert layer_crossing_mm(np.concatenate([lower, upper]), faces, layer) == 0.0
    assert layer_crossing_mm(np.concatenate([lower, upper]), faces, None) == 0.0


def test_wrong_side_mm_skips_vertices_between_layers():
    """A vertex whose faces belong to two layers is in neither (however the faces list it)."""
    from kitsuke.metrics import wrong_side_mm

    pos = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0.5, 0.5, -0.001]], dtype=float) * 0.01
    faces = np.array([[0, 1, 2], [0, 2, 3], [4, 0, 3]])
    layer = np.array([1, 2, 1], dtype=np.int8)
    # Vertex 3 has a face of layer 2 and one of layer 1: not counted as layer 1's (only vertices 1 and 4 are).
    assert len(wrong_side_mm(pos, faces, layer, 1, 2)) == 2
    assert len(wrong_side_mm(pos, faces, layer, 2, 1)) == 0


def test_vertex_strain_is_the_worst_edge_at_each_vertex():
    from kitsuke.app.strain_map import STOPS, strain_colors
    from kitsuke.metrics import vertex_strain

    pos = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]])
    faces = np.array([[0, 1, 2], [1, 3, 2]])
    rest = np.linalg.norm(pos[faces[:, [1, 2, 0]]] - pos[faces], axis=2)
    assert np.allclose(vertex_strain(pos, faces, rest), 0)
    moved = pos.copy()
    moved[3] = [1.1, 1.0, 0]  # only edges at vertex 3 stretch: 1-3 by 0.5 %, 3-2 by 10 %
    s = vertex_strain(moved, faces, rest)
    assert s[0] == 0 and s[3] == pytest.approx(0.1) and s[2] == pytest.approx(0.1)
    assert s[1] == pytest.approx(np.hypot(0.1, 1.0) - 1.0)
    c = strain_colors(np.array([0.0, 0.05, 1.0]), 0.05)
    assert tuple(c[0]) == STOPS[0][1] and tuple(c[1]) == STOPS[2][1] and tuple(c[2]) == STOPS[-1][1]
    with pytest.raises(InputError):
        vertex_strain(pos, faces, rest[:, :2])
