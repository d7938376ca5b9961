"""Wrap step 2: grow the garment ring by ring from the placed triangles, unfolding each new triangle from its
placed neighbour — from the placed cloth itself, not the body surface (the paper's Fig. 8 left) — with
relaxation and collision between rings.

A new triangle shares an edge (a, b) with an active triangle (a, b, d). Its third vertex c goes where the
triangle's rest shape puts it when hinged open to 180° about (a, b): in the neighbour's plane, on the side
away from d. Where several new triangles place the same vertex, it takes their mean; a vertex already placed
(a seam or a ring closing around the body) keeps its position and relaxation pulls the triangle together.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..cloth import ClothModel, ClothState

#: A triangle growing upwards (the y component of its direction away from the hinge at least this) does not turn
#: down: turning it would fold it back onto the cloth it grows from (a collar growing up round the neck).
HANG_UPWARD_LIMIT = 0.2


def frontier(model: ClothModel, active: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Inactive faces with an active edge neighbour: (faces (n,), local edge k (n,) of the first such neighbour)."""
    adj = model.face_adjacency
    nbr = (adj >= 0) & active[np.maximum(adj, 0)]
    ring = np.flatnonzero(~active & nbr.any(axis=1))
    return ring, np.argmax(nbr[ring], axis=1)


def unfold(
    model: ClothModel,
    positions: np.ndarray,
    ring: np.ndarray,
    k: np.ndarray,
    *,
    hang: float = 0.0,
    off_body: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Third-vertex positions of the faces `ring` unfolded across their local edge `k` from the neighbour there.

    hang : how far a triangle unfolded from cloth off the body turns down about its hinge edge: its direction
        away from the edge becomes that plus `hang` times the downward direction across the edge (0: straight on,
        the paper's unfolding; 2: about 63° down from a level start). Only where the triangle does not already
        grow upwards (it would fold back onto its neighbour) and, with `off_body` ((V,) bool), where both hinge
        vertices are off the body.
    Returns (vertex (n,) int64, position (n, 3) metres).
    """
    f = model.faces[ring]
    rows = np.arange(len(ring))
    k1, k2 = (k + 1) % 3, (k + 2) % 3
    a, b, c = f[rows, k], f[rows, k1], f[rows, k2]
    g = model.face_adjacency[ring, k]
    d = model.faces[g].sum(axis=1) - a - b
    rc = model.rest_corners[ring]
    ra, rb, rcc = rc[rows, k], rc[rows, k1], rc[rows, k2]
    eab, eac = rb - ra, rcc - ra
    ll = np.maximum(np.einsum("ij,ij->i", eab, eab), 1e-300)
    along = np.einsum("ij,ij->i", eac, eab) / ll  # fraction of the edge
    across = np.abs(eab[:, 0] * eac[:, 1] - eab[:, 1] * eac[:, 0]) / np.sqrt(ll)  # metres
    pa, pb, pd = positions[a], positions[b], positions[d]
    e = pb - pa
    eu = e / np.maximum(np.linalg.norm(e, axis=1, keepdims=True), 1e-300)
    w = pa - pd
    w -= np.einsum("ij,ij->i", w, eu)[:, None] * eu
    w = w / np.maximum(np.linalg.norm(w, axis=1, keepdims=True), 1e-300)
    if hang > 0:
        # Down, less its part along the hinge: a turn about the hinge keeps the triangle's rest shape.
        down = eu[:, 1:2] * eu
        down[:, 1] -= 1.0
        turn = w[:, 1] < HANG_UPWARD_LIMIT
        if off_body is not None:
            turn &= off_body[a] & off_body[b]
        w[turn] += hang * down[turn]
        w[turn] /= np.maximum(np.linalg.norm(w[turn], axis=1, keepdims=True), 1e-300)
    return c, pa + along[:, None] * e + across[:, None] * w


def grow(
    model: ClothModel,
    state: ClothState,
    placed: np.ndarray,
    relax_ring: Callable[[int], None],
    *,
    rings_per_relax: int = 1,
    hang: float = 0.0,
    hang_clearance_m: float = 0.03,
) -> int:
    """Grow `state.face_active` until no inactive face touches an active one; `placed` (V,) bool is updated in
    place. `relax_ring(ring_number)` runs after every `rings_per_relax` rings. Returns the number of rings.

    hang : see `unfold`; cloth counts as off the body where its tracked distance to the body
        (`state.contacts`, refreshed by the relaxation's collision update) is at least `hang_clearance_m`.
    """
    rings = 0
    while True:
        ring, k = frontier(model, state.face_active)
        if not len(ring):
            return rings
        off_body = None
        if hang > 0:
            c = state.contacts
            off_body = (c.face < 0) | (c.distance >= hang_clearance_m)
        vert, x = unfold(model, state.positions, ring, k, hang=hang, off_body=off_body)
        new = ~placed[vert]
        if new.any():
            v = vert[new]
            acc = np.zeros((model.n_vertices, 3))
            cnt = np.bincount(v, minlength=model.n_vertices).astype(np.float64)
            np.add.at(acc, v, x[new])
            got = cnt > 0
            pos = state.positions
            pos[got] = acc[got] / cnt[got, None]
            placed |= got
        state.face_active[ring] = True
        rings += 1
        if rings % rings_per_relax == 0:
            relax_ring(rings)
