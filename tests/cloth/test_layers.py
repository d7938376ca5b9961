"""Layered cloth (`ClothModel.face_layer`, `keep_layers`): the higher layer is kept outside the lower one."""

from __future__ import annotations

import numpy as np
import pytest

from kitsuke.cloth import BodyCollider, ClothModel, ClothParams, ClothState, collide, grid_sheet, keep_layers
from kitsuke.errors import InputError

from . import reference as ref
from .conftest import icosphere


def two_sheets(rng, *, under_z=0.0, over_z=-0.003, noise=0.001, n=9, spacing=0.015, inside_out=False):
    """Two sheets facing +z in one model: the lower layer (1) at z = under_z, the upper one (2) shifted (by 0.3 and
    0.6 cells: off the cells' diagonals, so no vertex is as near two faces) at z = over_z (below the lower one by
    default: the wrong order), both with height noise. inside_out: the lower sheet faces -z (its winding
    reversed, as where a collar lies twisted over)."""
    uv, f = grid_sheet(n, n, spacing)
    nv = len(uv)
    lower = f[:, ::-1] if inside_out else f
    faces = np.concatenate([lower, f + nv])
    rest = np.concatenate([uv[lower], uv[f]])
    layer = np.r_[np.ones(len(f), dtype=np.int8), np.full(len(f), 2, dtype=np.int8)]
    model = ClothModel.from_corners(faces, rest, params=ClothParams(), face_layer=layer)
    a = np.c_[uv, np.full(nv, under_z)]
    b = np.c_[uv + np.array([0.3, 0.6]) * spacing, np.full(nv, over_z)]
    pos = np.concatenate([a, b])
    pos[:, 2] += rng.uniform(-noise, noise, len(pos))
    return model, pos


def _over_minus_under(model, pos):
    """Height (+z) of each upper-layer vertex over the lower sheet's surface where it lies above it (brute
    force)."""
    out = []
    under = model.faces[model.face_layer == 1]
    for v in np.flatnonzero(model.vertex_layer == 2):
        k, q, d = ref.closest_on_mesh(pos[v], pos, under)
        a, b, c = pos[under[k]]
        n = ref.unit(np.cross(b - a, c - a))
        h = (pos[v] - q) @ (n if n[2] > 0 else -n)
        if d * d - h * h < 1e-8:  # above the sheet, not beside it
            out.append(h)
    return np.array(out)


def test_model_layers():
    """Vertex layers: a vertex whose faces share one layer has it; where layers meet (or meet no layer) 0."""
    uv, f = grid_sheet(4, 3, 0.02)
    layer = np.zeros(len(f), dtype=np.int8)
    layer[: len(f) // 2] = 3
    m = ClothModel.from_flat(f, uv)
    assert m.face_layer is None and not m.vertex_layer.any() and not len(m.layer_vertices)
    m = ClothModel.from_corners(f, uv[f], face_layer=layer)
    on = np.zeros(len(uv), dtype=bool)
    on[f[layer == 3].reshape(-1)] = True
    off = np.zeros(len(uv), dtype=bool)
    off[f[layer == 0].reshape(-1)] = True
    assert (m.vertex_layer[on & ~off] == 3).all() and (m.vertex_layer[off] == 0).all()
    assert (m.layers_at[on] & (1 << 3)).all() and not m.layers_at[~on].any()
    wider = m.with_params(ClothParams(friction=0.1, layer_reach_m=0.05))
    assert wider.face_layer is m.face_layer and wider.layer_cell_m > m.layer_cell_m
    # All zeros: no layers.
    assert ClothModel.from_corners(f, uv[f], face_layer=np.zeros(len(f), dtype=np.int8)).face_layer is None


@pytest.mark.parametrize(
    "layer",
    [np.ones(3, dtype=np.int8), np.full(24, 63), np.full(24, -1), np.full(24, 1.5)],
    ids=["shape", "too-high", "negative", "float"],
)
def test_model_rejects_bad_layers(layer):
    uv, f = grid_sheet(4, 3, 0.02)
    with pytest.raises(InputError, match="face_layer"):
        ClothModel.from_corners(f, uv[f], face_layer=layer)


def test_keep_layers_matches_brute_force(rng):
    """One Jacobi step of keep_layers against the brute-force reference: same moves on every vertex."""
    model, pos = two_sheets(rng, over_z=-0.002, noise=0.003)
    state = ClothState.new(model, pos.copy())
    moved = keep_layers(model, state)
    p = model.params
    want = ref.layer_moves(
        pos, model.faces, model.face_layer, model.vertex_layer, np.ones(len(pos), bool),
        p.layer_reach_m, p.layer_gap_m, p.max_step_m,
    )  # fmt: skip
    assert moved == int((np.abs(want).sum(axis=1) > 0).sum()) > 20
    np.testing.assert_allclose(state.positions - pos, want, atol=1e-12)


def test_keep_layers_puts_the_upper_layer_outside(rng):
    """The upper sheet starts 3 mm under the lower one: repeated steps put every vertex of it that lies over the
    lower sheet at least the gap (less a tenth of a millimetre) outside, and vertices beside the lower sheet's
    border, or farther than the reach, never move."""
    model, pos = two_sheets(rng)
    assert (_over_minus_under(model, pos) < 0).mean() > 0.9
    state = ClothState.new(model, pos.copy())
    for _ in range(10):
        keep_layers(model, state)
    h = _over_minus_under(model, state.positions)
    assert len(h) > 40 and h.min() >= model.params.layer_gap_m - 1e-4
    # Far apart (more than the reach): nothing is known, nothing moves.
    model, pos = two_sheets(rng, over_z=-0.05)
    state = ClothState.new(model, pos.copy())
    assert keep_layers(model, state) == 0 and (state.positions == pos).all()


def _body_below(state, distance_m=0.01):
    """Contacts as if a body lay under both sheets: tracked, `distance_m` away, outward +z."""
    c = state.contacts
    c.face[:] = 0
    c.normal[:] = (0.0, 0.0, 1.0)
    c.distance[:] = distance_m


def test_keep_layers_goes_by_the_body_where_a_layer_is_inside_out(rng):
    """The lower sheet lies inside out (its winding faces -z, the body is below): keep_layers still puts the upper
    sheet on the side away from the body, as the brute-force reference with the same rule does. With no body
    tracked, or the body farther than the reach (its nearest point says little), the windings alone decide, the
    same either way, and they disagree here: the upper sheet does not get the gap over the lower one."""
    model, pos = two_sheets(rng, over_z=-0.002, inside_out=True)
    state = ClothState.new(model, pos.copy())
    _body_below(state)
    p = model.params
    moved = keep_layers(model, state)
    want = ref.layer_moves(
        pos, model.faces, model.face_layer, model.vertex_layer, np.ones(len(pos), bool),
        p.layer_reach_m, p.layer_gap_m, p.max_step_m, outward=state.contacts.normal,
        near=np.full(len(pos), True),
    )  # fmt: skip
    assert moved > 20
    np.testing.assert_allclose(state.positions - pos, want, atol=1e-12)
    for _ in range(10):
        keep_layers(model, state)
    h = _over_minus_under(model, state.positions)
    assert len(h) > 40 and h.min() >= p.layer_gap_m - 1e-4
    by_winding = []
    for distance in (None, 0.05):
        state = ClothState.new(model, pos.copy())
        if distance is not None:
            _body_below(state, distance)
        for _ in range(10):
            keep_layers(model, state)
        by_winding.append(state.positions)
    np.testing.assert_array_equal(by_winding[0], by_winding[1])
    assert (_over_minus_under(model, by_winding[0]) < p.layer_gap_m - 1e-4).any()


def test_keep_layers_holds_pins_and_inactive_faces(rng):
    """Pinned vertices never move; inactive faces (not grown yet) are not a layer to keep; collide runs it."""
    model, pos = two_sheets(rng)
    pinned = np.zeros(len(pos), dtype=bool)
    pinned[model.vertex_layer == 2] = True
    state = ClothState.new(model, pos.copy(), pinned=pinned)
    assert keep_layers(model, state) > 0
    assert (state.positions[pinned] == pos[pinned]).all()
    assert (state.positions[~pinned, 2] <= pos[~pinned, 2]).all()  # the lower layer went down instead
    active = model.face_layer == 2
    state = ClothState.new(model, pos.copy(), face_active=active)
    assert keep_layers(model, state) == 0
    # collide (no body near) keeps the layers too.
    far = BodyCollider.from_mesh(icosphere(centre=(5.0, 5.0, 5.0)))
    state = ClothState.new(model, pos.copy())
    collide(model, state, far)
    assert not np.allclose(state.positions, pos)


def test_layer_planes_are_keep_layers_own_constraints(rng):
    """layer_planes: every upper-sheet vertex over the lower sheet (and lower-sheet vertex under the upper one)
    gets the plane keep_layers holds it to: a unit normal pointing out (+z) for the upper layer and in (-z) for the
    lower one, and a point on the other layer's face (its barycentric coordinates sum to 1); the vertices
    keep_layers moves are exactly those whose plane is violated (height along the normal under the gap)."""
    from kitsuke.cloth import layer_planes

    model, pos = two_sheets(rng, over_z=-0.002, noise=0.003)
    state = ClothState.new(model, pos.copy())
    planes = layer_planes(model, state)
    assert len(planes.vertex) > 60
    np.testing.assert_allclose(np.linalg.norm(planes.normal, axis=1), 1.0, atol=1e-12)
    upper = model.vertex_layer[planes.vertex] == 2
    assert upper.any() and (~upper).any()
    assert (planes.normal[upper, 2] > 0.8).all() and (planes.normal[~upper, 2] < -0.8).all()  # noisy sheets
    assert (model.face_layer[planes.face] != model.vertex_layer[planes.vertex]).all()
    np.testing.assert_allclose(planes.bary.sum(axis=1), 1.0, atol=1e-12)
    q = np.einsum("jk,jkc->jc", planes.bary, pos[model.faces[planes.face]])
    h = np.einsum("jc,jc->j", pos[planes.vertex] - q, planes.normal)
    violated = planes.vertex[h < model.params.layer_gap_m - 1e-12]
    keep_layers(model, state)
    moved = np.flatnonzero(np.abs(state.positions - pos).sum(axis=1) > 0)
    np.testing.assert_array_equal(np.sort(violated), moved)


def test_layer_planes_of_a_model_without_layers_are_empty():
    from kitsuke.cloth import layer_planes

    uv, f = grid_sheet(4, 3, 0.02)
    model = ClothModel.from_flat(f, uv)
    planes = layer_planes(model, ClothState.new(model, np.c_[uv, np.zeros(len(uv))]))
    assert len(planes.vertex) == len(planes.face) == len(planes.bary) == len(planes.normal) == 0


def test_refine_keeps_each_face_in_its_parents_layer(rng):
    from kitsuke.cloth import refine

    model, pos = two_sheets(rng)
    state = ClothState.new(model, pos)
    select = np.zeros(model.n_faces, dtype=bool)
    select[[5, 6, 7, model.n_faces - 3]] = True
    finer, _, r = refine(model, state, select=select)
    assert finer.n_faces > model.n_faces
    np.testing.assert_array_equal(finer.face_layer, model.face_layer[r.parent_face])
