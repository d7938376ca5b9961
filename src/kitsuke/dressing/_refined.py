"""The garment once the polish has refined it (`kitsuke.cloth.polish_refined`): faces put back in piece order,
and the stroke samples moved onto the new faces.

The refinement appends its faces in no piece order and replaces the faces the strokes were sampled on; the
outputs need each piece's faces contiguous (SPEC §3.3: `# kitsuke piece <name> <first> <last>`) and the
DressedGarment's tracks must index its own faces.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from ..cloth import ClothModel, ClothState, RefinedPolish
from ._place import StrokeTrack


@dataclass
class PieceOrdered:
    """A refined cloth with each piece's faces contiguous.

    model : the ClothModel with its faces reordered. order : (F',) int64, the refinement's face at each position.
    parent : (F',) int64, the face of the cloth given to the refinement that each face came from. piece_faces :
    (P, 2) int64 [start, stop) ranges. corner_uv : (F', 3, 2) float64 metres, each corner's pattern position in
    its piece. level, pending : the refinement's bookkeeping in the new order (for a later refinement).
    """

    model: ClothModel
    order: np.ndarray
    parent: np.ndarray
    piece_faces: np.ndarray
    corner_uv: np.ndarray
    level: np.ndarray | None = None
    pending: np.ndarray | None = None


def pieces_contiguous(refined: RefinedPolish, piece_faces: np.ndarray) -> PieceOrdered:
    """Reorder `refined`'s faces by the piece of their parent face (stable: the refinement's order within a
    piece). piece_faces : (P, 2) [start, stop) ranges of the unrefined faces; refined.corner_data must hold "uv"."""
    m = refined.model
    piece_of_face = np.searchsorted(piece_faces[:, 1], np.arange(int(piece_faces[-1, 1])), side="right")
    piece = piece_of_face[refined.parent_face]
    order = np.argsort(piece, kind="stable")
    counts = np.bincount(piece, minlength=len(piece_faces))
    stops = np.cumsum(counts)
    layer = None if m.face_layer is None else m.face_layer[order]
    model = ClothModel(m.faces[order], m.rest_corners[order], m.params, m.n_vertices, layer)
    return PieceOrdered(
        model=model,
        order=order,
        parent=refined.parent_face[order],
        piece_faces=np.stack([stops - counts, stops], axis=1).astype(np.int64),
        corner_uv=np.ascontiguousarray(refined.corner_data["uv"][order]),
        level=None if refined.level is None else refined.level[order],
        pending=None if refined.pending is None else refined.pending[order],
    )


def reorder_state(state: ClothState, ordered: PieceOrdered) -> ClothState:
    """`state` (of the refined cloth, in the refinement's face order) with its faces in `ordered`'s order (in
    place; returned for convenience)."""
    state.face_active = state.face_active[ordered.order]
    state._work.clear()  # caches keyed on face_active: its order changed, not its count
    return state


def remap_track(
    track: StrokeTrack, corner_uv: np.ndarray, piece_faces: np.ndarray, refined: PieceOrdered
) -> StrokeTrack:
    """`track` with its samples (faces of the unrefined garment, whose pattern corners are `corner_uv` (F, 3, 2)
    and pieces `piece_faces`) moved to the refined faces holding the same pattern points: the refinement lays
    new triangles over the same flat pattern, so each sample lies in exactly one of its piece's new faces."""
    point = np.einsum("ij,ijk->ik", track.bary, corner_uv[track.faces])  # (n, 2) metres, in the piece
    piece = np.searchsorted(piece_faces[:, 1], track.faces, side="right")
    faces = np.empty(len(point), dtype=np.int64)
    bary = np.empty((len(point), 3))
    for k in np.unique(piece):
        at = np.flatnonzero(piece == k)
        lo, hi = refined.piece_faces[k]
        c = refined.corner_uv[lo:hi]  # (m, 3, 2)
        e1, e2 = c[:, 1] - c[:, 0], c[:, 2] - c[:, 0]
        det = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]  # (m,)
        d = point[at, None, :] - c[None, :, 0]  # (n, m, 2)
        u = (d[..., 0] * e2[:, 1] - d[..., 1] * e2[:, 0]) / det
        v = (e1[:, 0] * d[..., 1] - e1[:, 1] * d[..., 0]) / det
        b = np.stack([1.0 - u - v, u, v], axis=-1)  # (n, m, 3)
        best = np.argmax(b.min(axis=-1), axis=1)  # the face the point is most inside
        faces[at] = lo + best
        bary[at] = np.clip(b[np.arange(len(at)), best], 0.0, 1.0)
        bary[at] /= bary[at].sum(axis=1, keepdims=True)
    return dataclasses.replace(track, faces=faces, bary=bary)
