"""Adaptive sqrt(3) subdivision (Kobbelt 2000) where cloth edges may cut into the body (the paper's edge test).

A sqrt(3) step inserts a vertex at the centroid of each chosen triangle (1-to-3 split) and then flips every old
edge between two triangles split at the same level, which gives well-shaped triangles a third of the size.
Inserting only interior points never makes T-junctions, so adaptive refinement stays conforming. Rules here:

- Neighbour rule (Kobbelt's, for graded levels): a chosen triangle forces every edge neighbour of a lower level
  to be split too, so levels across an edge differ by at most one.
- An old edge waits ("pending") until the triangle on its other side is split at the same level; then both flip.
- Edges on the boundary and seam edges (the two triangles place the shared vertices at different pattern
  positions) never flip, so the boundary and the seams keep their vertices; nor does an edge whose flip would
  fold the rest quad (it is not convex in the pattern).
- Positions and per-vertex data of a new vertex are the mean of its triangle's corners; the rest shape is carried
  per corner (the centroid of the triangle's pattern corners), so the total rest area is unchanged.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError
from ._collide import BodyCollider, track
from ._model import ClothModel, ClothState


@dataclass
class Refinement:
    """The result of `sqrt3_split`.

    faces : (F', 3) int64. rest_corners : (F', 3, 2) float64 metres. n_vertices : V' (old vertices keep their
    indices, new ones follow). parent_face : (F',) int64, the input face each output face lies in (for a flipped
    pair, the face holding its first corner). new_vertex_face : (V' - V,) int64, the input face each new vertex is
    the centroid of. split : (F,) bool, input faces that were split (the selection grown by the neighbour rule).
    level, pending : (F',) int64 / bool, subdivision bookkeeping to pass to the next call. flipped : edges flipped.
    vertex_data, face_data, corner_data : the carried attributes, same keys as given.
    """

    faces: np.ndarray
    rest_corners: np.ndarray
    n_vertices: int
    parent_face: np.ndarray
    new_vertex_face: np.ndarray
    split: np.ndarray
    level: np.ndarray
    pending: np.ndarray
    flipped: int
    vertex_data: dict[str, np.ndarray] = field(default_factory=dict)
    face_data: dict[str, np.ndarray] = field(default_factory=dict)
    corner_data: dict[str, np.ndarray] = field(default_factory=dict)


def _neighbours(faces: np.ndarray, n: int) -> np.ndarray:
    """(F, 3) face across local edge k (corners k, k+1) by undirected edge, -1 on the boundary."""
    a, b = faces.reshape(-1), faces[:, [1, 2, 0]].reshape(-1)
    key = np.minimum(a, b) * n + np.maximum(a, b)
    order = np.argsort(key, kind="stable")
    ks = key[order]
    same = np.flatnonzero(ks[1:] == ks[:-1])
    adj = np.full(len(key), -1, dtype=np.int64)
    adj[order[same]] = order[same + 1] // 3
    adj[order[same + 1]] = order[same] // 3
    return adj.reshape(-1, 3)


def _signed_area(c: np.ndarray) -> np.ndarray:
    e1, e2 = c[:, 1] - c[:, 0], c[:, 2] - c[:, 0]
    return 0.5 * (e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])


def sqrt3_split(
    faces: np.ndarray,
    rest_corners: np.ndarray,
    select: np.ndarray,
    *,
    n_vertices: int | None = None,
    level: np.ndarray | None = None,
    pending: np.ndarray | None = None,
    vertex_data: dict[str, np.ndarray] | None = None,
    face_data: dict[str, np.ndarray] | None = None,
    corner_data: dict[str, np.ndarray] | None = None,
) -> Refinement:
    """One adaptive sqrt(3) step on the faces `select` (F,) bool (see the module notes for the rules).

    faces : (F, 3) int64; rest_corners : (F, 3, 2) float64 metres (pattern position per corner).
    level, pending : from a previous call (default: all level 0, nothing pending).
    vertex_data : {name: (V, ...) float array} averaged into new vertices (positions (V, 3), uv, ...).
    face_data : {name: (F, ...) array} copied to the faces made from each face (piece id, ...).
    corner_data : {name: (F, 3, ...) float array} carried like the rest corners (per-corner uv, ...).

    The selection grown by the neighbour rule is split level by level, lowest first, flipping after each
    stage, so that a forced neighbour is split and flipped with its pending partner before that partner's own
    split (Kobbelt's order).
    """
    faces = np.ascontiguousarray(faces, dtype=np.int64)
    nf = len(faces)
    rc = np.asarray(rest_corners, dtype=np.float64)
    sel = np.asarray(select, dtype=bool)
    if faces.ndim != 2 or faces.shape[1] != 3 or rc.shape != (nf, 3, 2) or sel.shape != (nf,):
        raise InputError(
            f"sqrt3_split needs faces (F, 3), rest_corners (F, 3, 2), select (F,); got {faces.shape}, "
            f"{rc.shape}, {sel.shape}"
        )
    nv = int(faces.max()) + 1 if n_vertices is None else int(n_vertices)
    level = np.zeros(nf, dtype=np.int64) if level is None else np.asarray(level, dtype=np.int64)
    pending = np.zeros(nf, dtype=bool) if pending is None else np.asarray(pending, dtype=bool)
    if level.shape != (nf,) or pending.shape != (nf,):
        raise InputError(f"level and pending must have shape ({nf},)")
    vdata = {k: np.asarray(v) for k, v in (vertex_data or {}).items()}
    fdata = {k: np.asarray(v) for k, v in (face_data or {}).items()}
    cdata = {k: np.asarray(v, dtype=np.float64) for k, v in (corner_data or {}).items()}
    for name, arr, n in [(k, v, nv) for k, v in vdata.items()] + [(k, v, nf) for k, v in {**fdata, **cdata}.items()]:
        if len(arr) != n:
            raise InputError(f"attribute {name!r} has {len(arr)} rows, expected {n}")
    for name, arr in cdata.items():
        if arr.shape[:2] != (nf, 3):
            raise InputError(f"corner attribute {name!r} must have shape (F, 3, ...), got {arr.shape}")

    parent = np.arange(nf)
    split = np.zeros(nf, dtype=bool)
    new_vertex_face: list[np.ndarray] = []
    flipped = 0
    sel = sel.copy()
    while True:
        sel = _close(faces, nv, sel, level)
        if not sel.any():
            break
        stage = sel & (level == level[sel].min())
        split[parent[stage]] = True
        new_vertex_face.append(parent[stage])
        st = _split_stage(faces, rc, stage, nv, level, pending, vdata, cdata)
        faces, rc, nv, level, pending, vdata, cdata, rows, n_flip = st
        flipped += n_flip
        n_kids = 3 * int(stage.sum())
        sel = np.concatenate([sel[rows[: len(rows) - n_kids]], np.zeros(n_kids, dtype=bool)])  # rows keep their choice
        parent = parent[rows]
    return Refinement(
        faces=faces,
        rest_corners=rc,
        n_vertices=nv,
        parent_face=parent,
        new_vertex_face=np.concatenate(new_vertex_face) if new_vertex_face else np.zeros(0, dtype=np.int64),
        split=split,
        level=level,
        pending=pending,
        flipped=flipped,
        vertex_data=vdata,
        face_data={k: v[parent] for k, v in fdata.items()},
        corner_data=cdata,
    )


def _close(faces: np.ndarray, nv: int, sel: np.ndarray, level: np.ndarray) -> np.ndarray:
    """Neighbour rule: grow the selection over lower-level edge neighbours until it is closed."""
    adj = _neighbours(faces, nv)
    sel = sel.copy()
    while True:
        f, k = np.nonzero(adj[sel] >= 0)
        src = np.flatnonzero(sel)[f]
        g = adj[src, k]
        grow = g[(~sel[g]) & (level[g] < level[src])]
        if len(grow) == 0:
            return sel
        sel[grow] = True


def _split_stage(faces, rc, stage, nv, level, pending, vdata, cdata):
    """Split the faces `stage` (all of one level) 1-to-3 and flip the pending edges that became flippable.

    Returns the new faces, rest corners, vertex count, level, pending, vertex and corner data, the input row
    each output row comes from (kept rows first, then three children per split face) and the number of flips.
    """
    s = np.flatnonzero(stage)
    keep = np.flatnonzero(~stage)
    ns = len(s)
    cvert = nv + np.arange(ns)
    fs = faces[s]
    # Children of split face (v0, v1, v2) with centroid c: (v0, v1, c), (v1, v2, c), (v2, v0, c); the old edge is
    # each child's edge 0, pending until the face across it is split at the same level.
    kids = np.stack([np.stack([fs[:, k], fs[:, (k + 1) % 3], cvert], 1) for k in range(3)], 1).reshape(-1, 3)

    def split_corners(arr: np.ndarray) -> np.ndarray:
        a = arr[s]
        mid = a.mean(axis=1)
        return np.stack([np.stack([a[:, k], a[:, (k + 1) % 3], mid], 1) for k in range(3)], 1).reshape(
            -1, 3, *arr.shape[2:]
        )

    new_faces = np.concatenate([faces[keep], kids])
    new_rc = np.concatenate([rc[keep], split_corners(rc)])
    new_level = np.concatenate([level[keep], np.repeat(level[s] + 1, 3)])
    new_pending = np.concatenate([pending[keep], np.ones(3 * ns, dtype=bool)])
    rows = np.concatenate([keep, np.repeat(s, 3)])
    new_cdata = {k: np.concatenate([v[keep], split_corners(v)]) for k, v in cdata.items()}
    new_vdata = {k: np.concatenate([v, v[fs].mean(axis=1).astype(v.dtype, copy=False)]) for k, v in vdata.items()}

    # Flip pending old edges whose two faces are both pending at the same level.
    nv2 = nv + ns
    pf = np.flatnonzero(new_pending)
    a, b = new_faces[pf, 0], new_faces[pf, 1]
    key = np.minimum(a, b) * nv2 + np.maximum(a, b)
    order = np.argsort(key, kind="stable")
    ks = key[order]
    pair = np.flatnonzero(ks[1:] == ks[:-1])
    f1, f2 = pf[order[pair]], pf[order[pair + 1]]
    ok = (new_level[f1] == new_level[f2]) & (new_faces[f1, 0] == new_faces[f2, 1])  # same level, wound alike
    # Not a seam: both faces put the edge's ends at the same pattern position (and the same corner data).
    tol = 1e-7 + 1e-6 * np.linalg.norm(new_rc[f1, 1] - new_rc[f1, 0], axis=1)
    ok &= np.linalg.norm(new_rc[f1, 0] - new_rc[f2, 1], axis=1) <= tol
    ok &= np.linalg.norm(new_rc[f1, 1] - new_rc[f2, 0], axis=1) <= tol
    for v in new_cdata.values():
        width = int(np.prod(v.shape[2:], dtype=np.int64))  # (an empty pair list cannot reshape with -1)
        ok &= np.abs(v[f1, 0] - v[f2, 1]).reshape(len(f1), width).max(axis=1, initial=0) <= 1e-9
        ok &= np.abs(v[f1, 1] - v[f2, 0]).reshape(len(f1), width).max(axis=1, initial=0) <= 1e-9
    # Convex rest quad: both new triangles keep the parents' orientation.
    q1 = np.stack([new_rc[f1, 0], new_rc[f2, 2], new_rc[f1, 2]], 1)
    q2 = np.stack([new_rc[f2, 2], new_rc[f1, 1], new_rc[f1, 2]], 1)
    s1 = np.sign(_signed_area(new_rc[f1]))
    scale = np.abs(_signed_area(new_rc[f1])) + np.abs(_signed_area(new_rc[f2]))
    ok &= (s1 * _signed_area(q1) > 1e-6 * scale) & (s1 * _signed_area(q2) > 1e-6 * scale)
    f1, f2 = f1[ok], f2[ok]
    # (a, b, c1) + (b, a, c2) -> (a, c2, c1) + (c2, b, c1)
    fa, fb = new_faces[f1].copy(), new_faces[f2].copy()
    new_faces[f1] = np.stack([fa[:, 0], fb[:, 2], fa[:, 2]], 1)
    new_faces[f2] = np.stack([fb[:, 2], fa[:, 1], fa[:, 2]], 1)
    for arr in [new_rc, *new_cdata.values()]:
        ca, cb = arr[f1].copy(), arr[f2].copy()
        arr[f1] = np.stack([ca[:, 0], cb[:, 2], ca[:, 2]], 1)
        arr[f2] = np.stack([cb[:, 2], ca[:, 1], ca[:, 2]], 1)
    new_pending[f1] = new_pending[f2] = False
    return new_faces, new_rc, nv2, new_level, new_pending, new_vdata, new_cdata, rows, len(f1)


def colliding_edges(model: ClothModel, state: ClothState) -> np.ndarray:
    """(E,) bool: the paper's edge test on `model.edges`, from both ends, with the tracked body contacts.

    For edge AB of length L, P the body point nearest A at distance d (0 if A is inside) and q the angle between
    AB and the body's tangent plane at P, positive when AB heads into the body: the edge collides when sin q > 0,
    (d + L) sin q < L and (d + L) cos q < L — an edge that would dip into a body surface of curvature 1/L there.
    (For q <= 0 the edge heads away from the body; the inequalities alone would accept steep such edges.)
    Vertices without a tracked contact do not fire.
    """
    state.check(model)
    p = state.positions
    c = state.contacts
    e = model.edges
    out = np.zeros(len(e), dtype=bool)
    for a, b in ((e[:, 0], e[:, 1]), (e[:, 1], e[:, 0])):
        ab = p[b] - p[a]
        L = np.linalg.norm(ab, axis=1)
        d = np.maximum(c.distance[a], 0.0)
        sin_q = -np.einsum("ij,ij->i", ab, c.normal[a]) / np.maximum(L, 1e-300)
        cos_q = np.sqrt(np.clip(1.0 - sin_q**2, 0.0, 1.0))
        fires = (c.face[a] >= 0) & (sin_q > 0) & ((d + L) * sin_q < L) & ((d + L) * cos_q < L)
        out |= fires
    return out


def refine(
    model: ClothModel,
    state: ClothState,
    collider: BodyCollider | None = None,
    *,
    select: np.ndarray | None = None,
    level: np.ndarray | None = None,
    pending: np.ndarray | None = None,
    max_level: int = 4,
    vertex_data: dict[str, np.ndarray] | None = None,
    face_data: dict[str, np.ndarray] | None = None,
    corner_data: dict[str, np.ndarray] | None = None,
) -> tuple[ClothModel, ClothState, Refinement]:
    """Refine the cloth where it may cut into the body: one adaptive sqrt(3) step.

    select : (F,) bool faces to split; default: the active faces touching an edge that `colliding_edges` flags
        (with a collider, the contacts are tracked first). Faces at `max_level` or deeper are not chosen.
    level, pending : the bookkeeping of a previous refinement (Refinement.level / .pending), default none.
    The other attributes are carried as in `sqrt3_split`. Returns the new model (same params, and the same layers:
    each face keeps its parent's), the new state (positions, pins and contacts carried; new vertices free and
    tracked from their triangle's first corner) and the Refinement (whose vertex_data also holds "positions").
    """
    state.check(model)
    if collider is not None:
        track(model, state, collider)
    nf = model.n_faces
    lev = np.zeros(nf, dtype=np.int64) if level is None else np.asarray(level, dtype=np.int64)
    if lev.shape != (nf,):
        raise InputError(f"level must have shape ({nf},), got {lev.shape}")
    if select is None:
        hit = colliding_edges(model, state)
        sel = np.zeros(nf, dtype=bool)
        ef = model.edge_faces[hit].reshape(-1)
        sel[ef[ef >= 0]] = True
        sel &= state.face_active
    else:
        sel = np.asarray(select, dtype=bool)
        if sel.shape != (nf,):
            raise InputError(f"select must have shape ({nf},), got {sel.shape}")
    sel = sel & (lev < max_level)
    vd = {"positions": state.positions, **(vertex_data or {})}
    fd = {"_active": state.face_active, **(face_data or {})}
    if model.face_layer is not None:
        fd["_layer"] = model.face_layer
    r = sqrt3_split(
        model.faces,
        model.rest_corners,
        sel,
        n_vertices=model.n_vertices,
        level=lev,
        pending=pending,
        vertex_data=vd,
        face_data=fd,
        corner_data=corner_data,
    )
    active = r.face_data.pop("_active")
    # A split face stays in its parent's layer (the kimono's fronts keep their order once refined).
    layer = r.face_data.pop("_layer", None)
    new_model = ClothModel(r.faces, r.rest_corners, model.params, r.n_vertices, layer)
    first_corner = model.faces[r.new_vertex_face, 0]
    index = np.concatenate([np.arange(model.n_vertices), first_corner])
    new_state = ClothState(
        np.ascontiguousarray(r.vertex_data["positions"]),
        np.concatenate([state.pinned, np.zeros(len(first_corner), dtype=bool)]),
        active,
        state.contacts.take(index),
    )
    return new_model, new_state, r
