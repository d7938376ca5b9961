"""Which garments go round both legs at once (a skirt, a dress, a kimono), and the collider that fills the gap
between the legs for the wrap's shaping steps (growth, close, mend: `kitsuke.body.legs`)."""

from __future__ import annotations

import numpy as np

from ..body.legs import LegGap
from ..cloth import BodyCollider
from ..geometry.validate import edge_topology
from ..pattern import PatternMesh
from ._weld import Welded

#: An opening counts as round both legs when its placed points lie this far on both sides of the mid-plane, m.
SIDE_M = 0.03


def spans_legs(pm: PatternMesh, welded: Welded, crotch_y: float) -> bool:
    """Whether a garment has an opening below `crotch_y` that goes round both legs, by its pieces' placements
    (a skirt's hem does; each trouser leg's opening stays on its side). False without placements."""
    if not pm.placed.any():
        return False
    edges, count = edge_topology(welded.faces)
    rim = edges[count == 1]
    if not len(rim):
        return False
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    nodes, inv = np.unique(rim, return_inverse=True)
    inv = inv.reshape(-1, 2)
    graph = coo_matrix((np.ones(len(inv)), (inv[:, 0], inv[:, 1])), shape=(len(nodes), len(nodes)))
    _, loop = connected_components(graph, directed=False)
    # A placed pattern position of each garment vertex (the last pattern vertex sewn to it whose piece is placed).
    placed_v = pm.placed[pm.vertex_piece]
    where = np.full((welded.n_vertices, 3), np.nan)
    where[welded.vertex_of[placed_v]] = pm.positions_m[placed_v]
    p = where[nodes]
    low = np.isfinite(p[:, 0]) & (p[:, 1] < crotch_y)
    for k in np.unique(loop[low]):
        x = p[low & (loop == k), 0]
        if (x > SIDE_M).any() and (x < -SIDE_M).any():
            return True
    return False


def bridged(collider: BodyCollider, gap: LegGap) -> BodyCollider:
    """`collider` with the leg gap's capsules added (the same surface: cloth contacts stay valid)."""
    ends = np.concatenate([collider.capsule_ends, gap.ends])
    radii = np.concatenate([collider.capsule_radii, gap.radii])
    out = BodyCollider(collider.vertices, collider.faces, ends, radii, collider.source, collider.floor_y)
    out._surface = collider._surface  # one AABB tree for both
    return out
