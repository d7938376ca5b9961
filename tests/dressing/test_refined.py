"""A garment the polish refined (`_refined`): faces back in piece order, stroke samples moved onto the new faces."""

from __future__ import annotations

import numpy as np

from kitsuke.cloth import ClothModel, ClothState, PolishStats, RefinedPolish, grid_sheet, refine
from kitsuke.dressing._place import StrokeTrack
from kitsuke.dressing._refined import pieces_contiguous, remap_track


def two_pieces():
    """Two 6 x 5 sheets side by side as pieces 0 and 1 (faces [0, F/2) and [F/2, F)), bent into a quarter pipe so
    the cloth is curved; per-corner pattern positions in each piece's own coordinates."""
    uv, f = grid_sheet(6, 5, 0.02)
    nv = len(uv)
    faces = np.concatenate([f, f + nv])
    corners = np.concatenate([uv[f], uv[f]])
    flat = np.concatenate([uv, uv + [0.12, 0.0]])
    angle = flat[:, 0] / 0.4
    pos = np.c_[0.4 * np.sin(angle), flat[:, 1], 0.4 * np.cos(angle)]
    model = ClothModel.from_corners(faces, corners, n_vertices=2 * nv)
    return model, pos, np.array([[0, len(f)], [len(f), 2 * len(f)]])


def test_refined_faces_go_back_in_piece_order_and_samples_keep_their_place():
    model, pos, pieces = two_pieces()
    state = ClothState.new(model, pos)
    select = np.zeros(model.n_faces, dtype=bool)
    select[[3, 4, 10, pieces[1, 0] + 7, pieces[1, 0] + 8]] = True
    finer, fstate, r = refine(model, state, select=select, corner_data={"uv": model.rest_corners})
    refined = RefinedPolish(finer, fstate, r.parent_face, r.corner_data, 1, PolishStats())
    ordered = pieces_contiguous(refined, pieces)
    # Contiguous pieces, each face in the piece of the face it came from, the same faces as before.
    assert ordered.piece_faces[0, 0] == 0 and ordered.piece_faces[-1, 1] == finer.n_faces
    piece_of = np.searchsorted(pieces[:, 1], ordered.parent, side="right")
    for k, (lo, hi) in enumerate(ordered.piece_faces):
        assert (piece_of[lo:hi] == k).all()
    assert sorted(map(tuple, ordered.model.faces)) == sorted(map(tuple, finer.faces))
    np.testing.assert_array_equal(ordered.model.faces, finer.faces[ordered.order])
    # Stroke samples on the old faces (both pieces, some in refined faces) land on new faces at the same points:
    # the new vertices sit at their triangles' centroids, so the surface has not moved yet.
    rng = np.random.default_rng(0)
    old_faces = np.array([3, 4, 10, 0, 20, pieces[1, 0] + 7, pieces[1, 0] + 8, pieces[1, 0] + 30])
    bary = rng.dirichlet(np.ones(3), size=len(old_faces))
    track = StrokeTrack(1, old_faces, bary, np.zeros((2, 3)), 0.1, 0.1)
    moved = remap_track(track, model.rest_corners, pieces, ordered)
    assert (moved.faces < ordered.model.n_faces).all() and (moved.bary >= 0).all()
    np.testing.assert_allclose(moved.bary.sum(axis=1), 1.0)
    np.testing.assert_allclose(
        moved.points(fstate.positions, ordered.model.faces), track.points(pos, model.faces), atol=1e-12
    )
    # And in the pattern: the same pattern points.
    before = np.einsum("ij,ijk->ik", bary, model.rest_corners[old_faces])
    after = np.einsum("ij,ijk->ik", moved.bary, ordered.corner_uv[moved.faces])
    np.testing.assert_allclose(after, before, atol=1e-12)
