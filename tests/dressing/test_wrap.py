"""The wrap (SPEC §4.2): growth by unfolding (exact on flat cloth), stroke transfer, the GarmentCode shirt's
structure on mean_all (its quality, with the other shipped stroke files, is in test_packaged_strokes.py), the
demo's kimono end to end, and bad input."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from kitsuke.body import load_body
from kitsuke.cloth import ClothModel, ClothParams, ClothState, relax
from kitsuke.dressing import BodyStroke, GrowSettings, PatternStroke, SettleSettings, StrokePair, Strokes, read_strokes
from kitsuke.dressing._grow import grow, unfold
from kitsuke.dressing._place import _extended_coordinates
from kitsuke.dressing._solve import GlobalRelax
from kitsuke.dressing._weld import repair_corners, weld
from kitsuke.dressing.kimono import OBI_WIDTH_M, obi_band
from kitsuke.dressing.wrap import DressedGarment, WrapParams, wrap
from kitsuke.errors import InputError
from kitsuke.geometry import TriMesh
from kitsuke.geometry.validate import edge_topology
from kitsuke.metrics import wrong_side_mm
from kitsuke.pattern import KimonoSize, Pattern, Piece, load_pattern, make_kimono, mesh_pattern

ROOT = Path(__file__).resolve().parents[2]
SHIRT = ROOT / "tests" / "data" / "pattern" / "shirt_mean_specification.json"
MEAN_ALL = ROOT / "tests" / "data" / "bodies" / "mean_all.obj"
SHIRT_STROKES = ROOT / "src" / "kitsuke" / "assets" / "strokes" / "shirt_mean_all.json"


def _square(name: str = "square", size_cm: float = 20.0) -> Pattern:
    s = size_cm
    return Pattern("sheet", [Piece(name, np.array([[0.0, 0.0], [s, 0.0], [s, s], [0.0, s]]))], [])


def _sphere(radius_m: float = 0.3) -> TriMesh:
    import trimesh

    m = trimesh.creation.icosphere(subdivisions=4, radius=radius_m)
    return TriMesh(np.asarray(m.vertices, dtype=np.float64), np.asarray(m.faces, dtype=np.int64))


# -- growth -------------------------------------------------------------------------------------------------------
def test_unfold_reproduces_the_rest_triangle_on_flat_cloth():
    """Hinged open to 180° about the shared edge, the new vertex lands where the flat pattern has it."""
    rest = np.array([[0.0, 0.0], [1.0, 0.0], [0.3, 0.8], [0.6, -0.7]])
    faces = np.array([[0, 1, 2], [1, 0, 3]])
    model = ClothModel.from_flat(faces, rest)
    pos = np.c_[rest, np.zeros(4)]
    vert, x = unfold(model, pos, np.array([1]), np.array([0]))
    assert vert.tolist() == [3]
    np.testing.assert_allclose(x[0], pos[3], atol=1e-12)


def test_growth_of_a_flat_pattern_is_exact_without_relaxation():
    """Grown ring by ring from one triangle of a flat sheet laid in a tilted plane, the sheet is the pattern
    rotated into that plane: every edge keeps its rest length (strain 0 to 1e-9)."""
    pm = mesh_pattern(_square(), edge_length=3.0)
    w = weld(pm)
    model = ClothModel.from_corners(w.faces, w.rest_corners, n_vertices=w.n_vertices)
    uv = np.zeros((w.n_vertices, 2))
    uv[w.vertex_of] = pm.vertices_cm / 100.0
    rot = np.array([[0.8, 0.0, 0.6], [0.0, 1.0, 0.0]])  # pattern (u, v) -> a tilted plane in 3D
    start = np.zeros(model.n_faces, dtype=bool)
    start[0] = True
    placed = np.zeros(model.n_vertices, dtype=bool)
    placed[model.faces[0]] = True
    pos = np.zeros((model.n_vertices, 3))
    pos[placed] = uv[placed] @ rot
    state = ClothState.new(model, pos, face_active=start)
    rings = grow(model, state, placed, lambda _r: None)
    assert rings > 3 and state.face_active.all() and placed.all()
    e = model.edges
    length = np.linalg.norm(state.positions[e[:, 0]] - state.positions[e[:, 1]], axis=1)
    np.testing.assert_allclose(length, model.rest_lengths, rtol=1e-9)


def _two_triangles(angle_deg: float):
    """A rest pair (0, 1, 2) + (1, 0, 3) sharing the edge 0-1 along x; the first triangle placed in 3D tilted
    `angle_deg` above level about that edge, away from the second: (model, positions)."""
    rest = np.array([[0.0, 0.0], [1.0, 0.0], [0.3, -0.8], [0.6, 0.7]])
    model = ClothModel.from_flat(np.array([[0, 1, 2], [1, 0, 3]]), rest)
    t = np.radians(angle_deg)
    pos = np.zeros((4, 3))
    pos[1] = [1.0, 0.0, 0.0]
    pos[2] = [0.3, 0.8 * np.sin(t), 0.8 * np.cos(t)]  # the placed triangle lies on the +z side of the hinge
    return model, pos, rest


@pytest.mark.parametrize("angle", [0.0, 30.0])
def test_unfold_with_hang_turns_cloth_off_the_body_down_about_its_hinge(angle):
    """Hang turns the new triangle down about the shared edge: the new vertex keeps its rest distances to the
    edge's ends (a rigid turn of the rest triangle), goes lower than straight on, and by the documented amount
    (direction w + hang * down, normalised: from level, atan(2) = 63° down at hang 2)."""
    model, pos, rest = _two_triangles(angle)
    ring, k = np.array([1]), np.array([0])
    _, straight = unfold(model, pos, ring, k)
    _, hung = unfold(model, pos, ring, k, hang=2.0)
    for end in (0, 1):
        assert np.linalg.norm(hung[0] - pos[end]) == pytest.approx(np.linalg.norm(rest[3] - rest[end]), rel=1e-12)
    assert hung[0, 1] < straight[0, 1] - 0.3
    # Straight on goes down by `angle` (the placed triangle rises towards the hinge); w + 2 down from there.
    t = np.radians(angle)
    foot = np.array([0.6, 0.0, 0.0])  # where the new vertex's rest position projects onto the hinge
    w = (hung[0] - foot) / np.linalg.norm(hung[0] - foot)
    assert np.degrees(np.arcsin(-w[1])) == pytest.approx(np.degrees(np.arctan2(np.sin(t) + 2.0, np.cos(t))))


def test_unfold_with_hang_leaves_cloth_on_the_body_and_cloth_growing_up_alone():
    """No turn where the hinge touches the body (`off_body` False at either end), nor for cloth growing
    upwards (a collar round the neck would fold back onto itself)."""
    model, pos, _ = _two_triangles(0.0)
    ring, k = np.array([1]), np.array([0])
    _, straight = unfold(model, pos, ring, k)
    on_body = np.array([True, False, True, True])
    _, x = unfold(model, pos, ring, k, hang=2.0, off_body=on_body)
    np.testing.assert_array_equal(x, straight)
    model, pos, _ = _two_triangles(-60.0)  # the placed triangle below the hinge: the new one grows upwards
    _, straight = unfold(model, pos, ring, k)
    assert straight[0, 1] > 0.5
    _, x = unfold(model, pos, ring, k, hang=2.0)
    np.testing.assert_array_equal(x, straight)


def test_growth_with_hang_makes_a_level_sheet_hang():
    """A 20 cm sheet grown from a level triangle at one edge, with no body and the wrap's two relaxation
    iterations (no gravity) after each ring: straight on it stays level; with hang it curls down, its far edge
    well below where it started, its edges near their rest length (each triangle turns rigidly; a vertex placed
    by several triangles takes their mean, which the relaxation evens out; measured median |strain| 1.5 %, which
    the wrap's close takes out)."""
    pm = mesh_pattern(_square(), edge_length=3.0)
    w = weld(pm)
    model = ClothModel.from_corners(
        w.faces, w.rest_corners, n_vertices=w.n_vertices, params=ClothParams(gravity_step_m=0.0)
    )
    uv = np.zeros((w.n_vertices, 2))
    uv[w.vertex_of] = pm.vertices_cm / 100.0
    seed = int(np.argmin(uv[model.faces].mean(axis=1)[:, 0]))  # a face on the sheet's u = 0 side
    ys = []
    for hang in (0.0, 2.0):
        placed = np.zeros(model.n_vertices, dtype=bool)
        placed[model.faces[seed]] = True
        pos = np.zeros((model.n_vertices, 3))
        pos[placed] = np.c_[uv[placed, 0], np.zeros(placed.sum()), uv[placed, 1]]  # level: the xz plane
        start = np.zeros(model.n_faces, dtype=bool)
        start[seed] = True
        state = ClothState.new(model, pos, face_active=start)
        grow(model, state, placed, lambda _r, s=state: relax(model, s, iterations=2), hang=hang)
        far = uv[:, 0] > 0.19
        ys.append(state.positions[far, 1].mean())
        e = model.edges
        strain = np.linalg.norm(state.positions[e[:, 0]] - state.positions[e[:, 1]], axis=1) / model.rest_lengths - 1
    assert abs(ys[0]) < 1e-6
    assert ys[1] < -0.1
    assert np.median(np.abs(strain)) < 0.03


def test_weld_shares_every_seam_vertex():
    pm = mesh_pattern(load_pattern(SHIRT), edge_length=3.0)
    w = weld(pm)
    for pairs in pm.seam_vertices:
        assert (w.vertex_of[pairs[:, 0]] == w.vertex_of[pairs[:, 1]]).all()
    assert w.n_vertices < pm.n_vertices
    np.testing.assert_allclose(w.rest_corners * 100.0, pm.vertices_cm[pm.faces[w.face_order]])
    # Pieces stay contiguous in the garment's face order.
    assert (w.face_order[w.piece_faces[0, 0] : w.piece_faces[0, 1]] < pm.piece_faces[0, 1]).all()


@pytest.mark.parametrize("edge_cm", [1.5, 3.0])
def test_repair_corners_makes_the_sewn_kimono_manifold(edge_cm):
    """A kimono sleeve with square corners (sleeve_round 0): the bag's bottom and outer side are both sewn to the
    sleeve itself and meet at a corner: sewn as meshed, the two corner triangles coincide and their inner edge is
    used by 4 triangles. repair_corners splits that inner edge (one new vertex per affected corner, inside its
    piece); then every sewn edge is used by at most 2 triangles, every seam is still shared, and each piece keeps
    one orientation. (The default rounded corner sews without this.)"""
    assert edge_topology(_sewn_faces(mesh_pattern(make_kimono(), edge_length=edge_cm)))[1].max() <= 2
    pm = mesh_pattern(make_kimono(KimonoSize(sleeve_round=0)), edge_length=edge_cm)
    _, raw = edge_topology(_sewn_faces(pm))
    assert raw.max() > 2
    with pytest.raises(InputError, match="more than two"):
        weld(pm)
    fixed = repair_corners(pm)
    assert 0 < fixed.n_vertices - pm.n_vertices <= 4 and fixed.n_faces == pm.n_faces + 2 * (
        fixed.n_vertices - pm.n_vertices
    )
    w = weld(fixed)
    _, counts = edge_topology(w.faces)
    assert counts.max() <= 2
    for pairs in fixed.seam_vertices:
        assert (w.vertex_of[pairs[:, 0]] == w.vertex_of[pairs[:, 1]]).all()
    for k, (a, b) in enumerate(fixed.piece_faces):
        assert (fixed.vertex_piece[fixed.faces[a:b]] == k).all()
        t = fixed.vertices_cm[fixed.faces[a:b]]
        d1, d2 = t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]
        area = d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]
        assert (area > 0).all() or (area < 0).all()

    # The total pattern area is unchanged (the split faces tile their originals).
    def total(m):
        t = m.vertices_cm[m.faces]
        d1, d2 = t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]
        return np.abs(d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]).sum()

    assert total(fixed) == pytest.approx(total(pm), rel=1e-12)
    # A pattern that sews into a manifold is returned as is.
    shirt = mesh_pattern(load_pattern(SHIRT), edge_length=3.0)
    assert repair_corners(shirt) is shirt


def _sewn_faces(pm):
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    pairs = np.concatenate(pm.seam_vertices)
    g = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(pm.n_vertices,) * 2)
    return connected_components(g, directed=False)[1][pm.faces]


def test_stroke_coordinates_continue_past_the_ends():
    """Points past a stroke's ends get s < 0 or s > length and their offset from the end segment's line, so the
    transfer keeps the triangles that stick out past an end in shape (clamping s folded them: 88 % strain)."""
    stroke = np.array([[0.0, 0.0], [10.0, 0.0]])
    pts = np.array([[-2.0, 1.0], [12.0, -3.0], [5.0, 2.0]])
    s, off = _extended_coordinates(pts, stroke)
    np.testing.assert_allclose(s, [-2.0, 12.0, 5.0])
    np.testing.assert_allclose(off, [1.0, -3.0, 2.0])


def test_global_relax_converges_where_jacobi_crawls():
    """A flat 30 cm sheet stretched by 1.3 along one axis (mean edge strain 15 %: the large-scale distortion
    that growth leaves where pieces grown from different strokes meet). 20 iterations of GlobalRelax bring the
    mean strain below 0.5 % (measured 0.0075 %); 20 iterations of the Jacobi relax leave 11 %."""
    from kitsuke.cloth import grid_sheet, relax

    uv, faces = grid_sheet(21, 21, 0.015)
    model = ClothModel.from_flat(faces, uv)
    pos = np.c_[uv[:, 0] * 1.3, uv[:, 1], np.zeros(len(uv))]
    e = model.edges

    def strain(p):
        return np.abs(np.linalg.norm(p[e[:, 0]] - p[e[:, 1]], axis=1) / model.rest_lengths - 1).mean()

    a = ClothState.new(model, pos.copy())
    g = GlobalRelax(model, np.zeros(model.n_vertices, dtype=bool))
    for _ in range(20):
        g.step(a, None)
    b = ClothState.new(model, pos.copy())
    relax(model.with_params(model.params.__class__(gravity_step_m=0.0)), b, iterations=20)
    assert strain(a.positions) < 0.005
    assert strain(b.positions) > 0.05


# -- a sheet on a sphere -------------------------------------------------------------------------------------------
def _sheet_strokes(radius_m: float) -> Strokes:
    # A 16 cm stroke through the middle of the sheet onto a 16 cm arc over the top of the sphere.
    ang = np.linspace(-0.08, 0.08, 9) / radius_m
    body = np.c_[radius_m * np.sin(ang), radius_m * np.cos(ang), np.zeros_like(ang)]
    return Strokes([StrokePair(1, PatternStroke("square", [[2.0, 10.0], [18.0, 10.0]]), BodyStroke(points=body))])


def test_wrap_sheet_on_sphere():
    """A 20 cm square wrapped over a 30 cm sphere by one stroke drapes over it: nothing inside, the stroke stays
    on its body stroke (within 1 cm). Measured: strain mean 1.1 %, max 22 % (a flat square cannot lie on a
    sphere without strain where its corners fold), no inverted triangle (one in a corner fold before untangling)."""
    sphere = _sphere(0.3)
    g = wrap(
        sphere,
        _square(),
        _sheet_strokes(0.3),
        params=WrapParams(edge_length_cm=2.0, settle=SettleSettings(iterations=40)),
    )
    assert isinstance(g, DressedGarment)
    r = g.report
    assert r.penetration_count == 0 and r.inverted_count == 0 and r.seam_gap_mm == 0.0
    radius = np.linalg.norm(g.positions, axis=1)
    assert radius.min() > 0.3 - 2e-3
    assert g.max_stroke_residual_m < 0.01  # measured 4-5 mm (lift + contact offset)
    assert r.strain_mean < 0.015 and r.strain_max < 0.3
    assert set(g.timings) >= {"place", "grow", "close", "settle", "finish", "untangle", "wrap"}


# -- the shirt on mean_all -----------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def shirt() -> DressedGarment:
    body = load_body(MEAN_ALL)
    return wrap(body, load_pattern(SHIRT), read_strokes(SHIRT_STROKES))


def test_global_settle_strains_the_shirt_less(shirt):
    """settle="global" (`_solve.gravity_settle`) on its own, without the finish and the length restoration that
    follow either settle: the same shirt, less strained than after the Jacobi settle (measured 2026-11-24: 1.8 %
    against 2.6 % mean), still outside the body and without folded triangles."""
    body, pattern, strokes = load_body(MEAN_ALL), load_pattern(SHIRT), read_strokes(SHIRT_STROKES)
    bare = WrapParams().changed({"lengths.finish_iterations": 0, "lengths.sweeps": 0, "polish.rounds": 0})
    jacobi = wrap(body, pattern, strokes, params=bare)
    g = wrap(body, pattern, strokes, params=bare.changed({"settle.method": "global", "settle.iterations": 30}))
    r = g.report
    assert r.strain_mean < jacobi.report.strain_mean - 0.002
    assert r.penetration_count == 0 and r.inverted_count == 0 and r.seam_gap_mm == 0.0
    assert g.max_stroke_residual_m < 0.025


def test_shirt_on_mean_all_structure(shirt):
    """The sewn shirt: fewer vertices than its pattern mesh (seams shared) plus those the polish's refinement
    added, every face in its piece's contiguous range, and the pattern's area per piece kept exactly (refinement
    lays finer triangles over the same flat pattern)."""
    pm = mesh_pattern(load_pattern(SHIRT))
    assert len(shirt.faces) >= pm.n_faces
    added = (len(shirt.faces) - pm.n_faces) // 2  # each sqrt(3) split: one vertex, two more faces
    assert shirt.n_vertices - added < pm.n_vertices
    assert len(shirt.pattern_vertex) == pm.n_vertices and shirt.pattern_vertex.min() >= 0
    assert len(np.unique(shirt.pattern_vertex)) == shirt.n_vertices - added  # seam vertices shared
    assert np.isfinite(shirt.positions).all()
    assert shirt.piece_faces[0, 0] == 0 and shirt.piece_faces[-1, 1] == len(shirt.faces)
    assert (shirt.piece_faces[1:, 0] == shirt.piece_faces[:-1, 1]).all()

    def areas(corners: np.ndarray, ranges: np.ndarray) -> np.ndarray:
        e1, e2 = corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]
        a = 0.5 * np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])
        return np.array([a[lo:hi].sum() for lo, hi in ranges])

    pattern_areas = areas(pm.vertices_cm[pm.faces] / 100.0, pm.piece_faces)
    np.testing.assert_allclose(areas(shirt.corner_uv, shirt.piece_faces), pattern_areas, rtol=1e-9)
    # corner_uv (metres) reproduces the model's rest lengths on the first edge of every face.
    uv = shirt.corner_uv
    rest = np.linalg.norm(uv[:, 1] - uv[:, 0], axis=1)
    cur = np.linalg.norm(shirt.positions[shirt.faces[:, 1]] - shirt.positions[shirt.faces[:, 0]], axis=1)
    assert np.median(np.abs(cur / rest - 1)) < 0.06


# -- the kimono on the default body --------------------------------------------------------------------------------
def test_kimono_on_default_body(body, dressed_kimono):
    """default_kimono() with the shipped strokes at 1.5 cm edges, its waist held in the obi band and its sleeves
    hanging (what `kitsuke demo` dresses), its left front kept over the right: every issue 3 target met.
    Measured 2026-11-25 (stroke tethers at 8 mm, hang 2, sleeve corners rounded 2 cm, layers 2 mm apart, 3 mm
    off the body, the okumi's top cut on the slant, the shoulder strokes from 6 cm past the neck point, the wrap's
    polish with refinement kept): no penetration, seams shared, no folded triangle, strain mean 0.33 % and max
    4.8 % (on the right front under the left, at the chest), stroke residual 8.0 mm; over the default body moved
    by 1 nm (four seeds) 0.36-0.38 % / 4.8-4.9 %. With the shoulder strokes from 1.5 cm past the neck point:
    14.1-14.4 % there; with the okumi cut square as well: 0.53 % / 47 % (where the collars cross: the straight
    collar turned 90° at the okumi's corner), its polish not kept; before the layers: 0.47 % / 41 %, with the
    fronts through each other; with square sleeve corners: 0.52 % / 65 %."""
    g = dressed_kimono
    r = g.report
    assert r.penetration_count == 0 and r.seam_gap_mm == 0.0
    assert r.strain_mean <= 0.01  # measured 0.0033-0.0038
    assert r.strain_max <= 0.05  # measured 0.048-0.049
    assert r.inverted_count == 0
    assert g.max_stroke_residual_m <= 0.01  # measured 0.0080: issue 3's target
    _, counts = edge_topology(g.faces)
    assert counts.max() <= 2
    # It hangs from the shoulders down to the ankles, above the floor; the obi band is held.
    y = g.positions[:, 1]
    assert 1.35 < y.max() < 1.60 and 0.0 < y.min() < 0.15
    low, high = obi_band(body)
    assert 0.9 < low < 1.05 and high - low == pytest.approx(OBI_WIDTH_M)
    # The band held the cloth over the torso, not the sleeves hanging over the forearms at that height; the
    # finish (no gravity) let it go, so it may have moved a little (measured 2026-11-26: up to 11.3 mm below it).
    assert g.pinned.sum() > 100 and ((y[g.pinned] >= low - 0.02) & (y[g.pinned] <= high + 0.02)).all()
    sleeves = np.zeros(g.n_vertices, dtype=bool)
    for k, name in enumerate(g.piece_names):
        if name.startswith("sode"):
            sleeves[g.faces[g.piece_faces[k, 0] : g.piece_faces[k, 1]].reshape(-1)] = True
    assert not (g.pinned & sleeves).any()


def test_kimono_left_front_lies_over_the_right(body, dressed_kimono):
    """SPEC §5.4: left over right. The left front (okumi, body panel front, collar end: layer 2) stays outside
    the right one (layer 1) through the wrap, outside meaning away from the body (the right collar lies inside
    out where the collars cross: by its winding alone, left-front vertices there count as inside it). Measured
    2026-11-25 on the default body and on five copies moved by 1 nm (the wrap is chaotic in rounding), the okumi's
    top cut on the slant: no vertex of either front on the wrong side of the other (the right front's at least
    1.1 mm under the left, the left's at least 2.0 mm over the right). With the okumi cut square: up to 3.3 mm
    where the collars crossed. Without the layers: 370 right-front vertices outside the left front, up to 3 cm."""
    g = dressed_kimono
    under = wrong_side_mm(g.positions, g.faces, g.model.face_layer, 1, 2, body.mesh)
    over = wrong_side_mm(g.positions, g.faces, g.model.face_layer, 2, 1, body.mesh)
    assert under.max() <= 1.0 and over.max() <= 1.0


def test_kimono_sleeves_hang_below_the_arms(body, dressed_kimono):
    """With `hang` (kimono_params) the sleeves' lower halves hang as bags: each sleeve's lowest point is far below
    the elbow. Measured 2026-11-25: 34.5 / 36.3 cm below it; without hang the sleeves wrapped the forearms in
    bunches, 8 / 13 cm below it (a real kimono's sleeve is 49 cm deep from its crease on top of the arm)."""
    from kitsuke.skeleton import INDEX

    g = dressed_kimono
    for k, name in enumerate(g.piece_names):
        if not name.startswith("sode"):
            continue
        v = np.unique(g.faces[g.piece_faces[k, 0] : g.piece_faces[k, 1]])
        elbow = body.rig.joints[INDEX[f"{name[5]}_elbow"]]
        assert elbow[1] - g.positions[v, 1].min() > 0.25, name


def test_kimono_params():
    """kimono_params: hang and the obi band for a rigged body; a band or hang given is kept; no band without a
    rig; is_kimono reads the pattern's meta (kept through the pattern JSON)."""
    from kitsuke.body import default_body
    from kitsuke.dressing.kimono import KIMONO_HANG, KIMONO_OFFSET_M, is_kimono, kimono_params

    b = default_body()
    p = kimono_params(b)
    assert p.grow.hang == KIMONO_HANG and p.settle.hold_band_m == obi_band(b)
    assert p.cloth.contact_offset_m == KIMONO_OFFSET_M > WrapParams().cloth.contact_offset_m  # over an under-kimono
    # The polish is the wrap's own (its layers now hold, so it is kept: 4.8 % max strain where it was 37 %).
    assert p.polish == WrapParams().polish
    hung = WrapParams(grow=GrowSettings(hang=1.0))
    assert kimono_params(b, hung).grow.hang == 1.0
    assert kimono_params(b, hung, hang=0.0).grow.hang == 0.0
    banded = WrapParams(settle=SettleSettings(hold_band_m=(0.5, 0.6)))
    assert kimono_params(b, banded).settle.hold_band_m == (0.5, 0.6)
    assert kimono_params(b.mesh).settle.hold_band_m is None
    assert is_kimono(make_kimono()) and not is_kimono(load_pattern(SHIRT))


# -- bad input -----------------------------------------------------------------------------------------------------
def test_wrap_rejects_an_unreached_piece():
    pat = Pattern("two", [_square("square").pieces[0], _square("other").pieces[0]], [])
    with pytest.raises(InputError, match="no stroke reaches piece"):
        wrap(_sphere(), pat, _sheet_strokes(0.3), params=WrapParams(edge_length_cm=4.0))


def test_wrap_rejects_a_missing_piece_and_bad_params():
    bad = Strokes(
        [
            StrokePair(
                1, PatternStroke("nope", [[2.0, 10.0], [18.0, 10.0]]), BodyStroke(points=[[0, 0.3, 0], [0.1, 0.28, 0]])
            )
        ]
    )
    with pytest.raises(InputError, match="nope"):
        wrap(_sphere(), _square(), bad)
    # Each setting checked in its group, named as the group and field.
    bad_settings = {
        "grow.rings_per_relax": 0,
        "close.cg_iterations": 0,
        "settle.hold_band_m": (1.0, 0.9),
        "close.stroke_hold": -0.1,
        "untangle.rounds": -1,
        "settle.method": "verlet",
        "settle.stick_weight": -1.0,
        "lengths.sweeps": -1,
        "settle.hold_reach_m": 0.0,
        "untangle.bend": -0.1,
        "lengths.collide_every": 0,
        "grow.hang_clearance_m": -0.01,
        "grow.bridge_legs": "yes",
        "polish.passes": 1.5,
        "settle.release_strokes": 0,
    }
    bad_settings |= {f"lengths.over_relaxation={v}": v for v in (0.5, 2.0, float("nan"))}
    bad_settings |= {f"lengths.chebyshev_rho={v}": v for v in (0.0, 1.0, float("nan"))}
    bad_settings |= {f"tethers.reach_m={v}": v for v in (0.0, -0.01, float("nan"))}
    bad_settings |= {f"grow.hang={v}": v for v in (-1.0, float("nan"))}
    for key, value in bad_settings.items():
        name = key.split("=")[0]
        field = name.split(".")[1]
        with pytest.raises(InputError, match=rf"{field}"):
            WrapParams().changed({name: value})
    with pytest.raises(InputError, match="hold_reach_m"):
        WrapParams.strokes_held(settle=SettleSettings(hold_reach_m=float("nan")))
    with pytest.raises(InputError, match="no wrap setting 'polish.roundz'"):
        WrapParams().changed({"polish.roundz": 1})
    with pytest.raises(InputError, match="no wrap setting 'glow.hang'"):
        WrapParams().changed({"glow.hang": 1})
    with pytest.raises(InputError, match="WrapParams.close must be a CloseSettings"):
        WrapParams(close=3)
    with pytest.raises(InputError, match="no strokes"):
        wrap(_sphere(), _square(), Strokes([]))
    garment_target = Strokes(_sheet_strokes(0.3).pairs, target="garment")
    with pytest.raises(InputError, match="re-wrap"):
        wrap(_sphere(), _square(), garment_target)
