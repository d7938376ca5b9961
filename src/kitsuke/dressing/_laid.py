"""Pieces laid at their placement instead of grown: the wrap's answer to a piece that growth took round the wrong
side of the body.

Growth unfolds a piece without strokes from its neighbours across their seams (`_grow`). A skirt's front whose only
neighbours are the back's side seams grows on from them straight out behind the body, and turns down as it hangs:
it never reaches the front, and the close cannot pull it through the legs (measured on GarmentCode designs with
one stroke, on the back: the front ended at the back right or left, `outcome.wrong_side_pieces`). Such a piece is
laid instead where the pattern's placement puts it, turned about the body's vertical axis and moved up or down as
the stroked pieces were placed (GarmentCode lays each panel flat around the body, the front in front of it), and
its seams are closed from there like any other: the close pulls its edges round to the neighbours it is sewn to.

The same answers cloth torn round a limb: growing a bodice from a stroke on the chest takes its side over the upper
arm, and the side seam then closes with the arm inside the torso. Every piece laid at its placement (the stroke
triangles still on their strokes) and sewn by the close puts the side seam under the arm, as GarmentCode's own
simulator does from the same placement (measured: a sleeveless fitted dress, torn at the armpit when grown, worn
with the arms through its armholes when laid).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from ..pattern import PatternMesh
from ._place import Placement
from ._weld import Welded
from .outcome import mean_turn


def lay_at_placement(
    pm: PatternMesh, welded: Welded, placement: Placement, pieces: list[int], axis: np.ndarray
) -> Placement:
    """`placement` with the pieces `pieces` (indices into pm.piece_names, each with a placement) laid too: their
    vertices not placed by a stroke at the pattern's placed positions (`pm.positions_m`), turned about the vertical
    axis through `axis` (x, z metres) by the stroked vertices' mean turn from their placed positions and moved by
    their mean height change; their faces join the seed faces (active from the start; not pinned)."""
    v = welded.vertex_of
    stroked = placement.placed[v]
    placed_piece = np.repeat(pm.placed, np.diff(pm.piece_vertices, axis=1).reshape(-1))
    ref = stroked & placed_piece
    before, after = pm.positions_m[ref], placement.positions[v[ref]]
    turn = mean_turn(before[:, [0, 2]] - axis, after[:, [0, 2]] - axis)
    rise = float(np.mean(after[:, 1] - before[:, 1])) if len(before) else 0.0
    c, s = np.cos(turn), np.sin(turn)
    positions, placed, seed = placement.positions.copy(), placement.placed.copy(), placement.seed_faces.copy()
    for k in pieces:
        a, b = pm.piece_vertices[k]
        p = pm.positions_m[a:b]
        x, z = p[:, 0] - axis[0], p[:, 2] - axis[1]
        # A turn by `turn` about +Y takes direction angle atan2(x, z) to atan2(x, z) + turn (as `mean_turn` measures).
        laid = np.c_[axis[0] + c * x + s * z, p[:, 1] + rise, axis[1] - s * x + c * z]
        w = v[a:b]
        new = ~placed[w]
        positions[w[new]] = laid[new]
        placed[w] = True
        f0, f1 = welded.piece_faces[k]
        seed[f0:f1] = True
    return dataclasses.replace(placement, positions=positions, placed=placed, seed_faces=seed)
