"""The relaxation step of the paper (not physics: no velocities; vertices move directly each iteration)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from . import _kernels as K
from ._collide import BodyCollider, CollisionStats, collide, vertex_active
from ._model import ClothModel, ClothState


@dataclass
class RelaxStats:
    """What `relax` did.

    iterations : iterations run.
    max_step_m : the largest vertex move of the last iteration, metres (before collision), a convergence measure.
    flipped : triangles found folded over their neighbours (or collapsed) in the last iteration.
    searches : global nearest-point searches over all iterations.
    collision : the last iteration's collision update (None without a collider).
    """

    iterations: int = 0
    max_step_m: float = 0.0
    flipped: int = 0
    searches: int = 0
    collision: CollisionStats | None = None


def _work(model: ClothModel, state: ClothState) -> dict:
    w = state._work
    if w.get("n_relax") != (model.n_vertices, model.n_faces):
        nf, nh, nv = model.n_faces, len(model.hinges), model.n_vertices
        w["n_relax"] = (nv, nf)
        w["normals"] = np.zeros((nf, 3))
        w["ref"] = np.zeros((nf, 3))
        w["flipped"] = np.zeros(nf, dtype=np.uint8)
        w["goals"] = np.zeros((nf, 3, 3))
        w["hinge"] = np.zeros((nh, 4, 3))
        w["out"] = np.zeros((nv, 3))
        w["step"] = np.zeros(nv)
        w["by_height"] = np.arange(nv, dtype=np.int64)
        w["order"] = np.zeros(nv, dtype=np.int64)
        w["rank"] = np.zeros(nv, dtype=np.int64)
    return w


def _check(model: ClothModel, state: ClothState) -> None:
    if not isinstance(state, ClothState):
        raise InputError("relax needs a ClothModel and a ClothState")
    state.check(model)


def _near_free(model: ClothModel, state: ClothState) -> np.ndarray:
    """(F,) bool: the active triangles within two rings of a free vertex: those a free vertex's move reads (its own
    triangles, their neighbours across an edge for the un-flipping reference, both triangles of its hinges)."""
    free = ~state.pinned
    ring1 = np.zeros(model.n_vertices, dtype=bool)
    ring1[model.faces[free[model.faces].any(axis=1)].reshape(-1)] = True
    return state.face_active & ring1[model.faces].any(axis=1)


def relax(
    model: ClothModel,
    state: ClothState,
    collider: BodyCollider | None = None,
    *,
    iterations: int = 1,
    around_free: bool = False,
) -> RelaxStats:
    """Relax the cloth for `iterations` iterations, in place on `state`.

    One iteration: (1) every active triangle fits its rest shape (rotated to best match the current corners, in
    the triangle's plane — or, for a triangle folded over its neighbours, in the plane facing their way, which
    un-flips it); (2) every interior edge's two triangles are turned towards flat (180°); (3) each vertex moves
    by `stretch_stiffness` times the mean of its triangles' goals, `bend_stiffness` times the mean of its hinges'
    moves, and `gravity_step_m` down; where it touches the body and presses into it, Coulomb `friction` holds
    back its move along the body;
    (4) with gravity on, strain limiting shortens edges to at most 1 + `max_stretch` of their rest length,
    from the supports (pins, and vertices resting on body surfaces that face up) and then from the top down, so
    that hanging cloth hangs from them; (5) with a collider, the cloth is pushed out of the capsules and the
    body (`collide`). Pinned vertices never move. Parameters: `model.params` (ClothParams).
    `state.positions` keeps its identity (the same array is updated).

    around_free : work only on the triangles within two rings of the free (unpinned) vertices, and after the first
        iteration collide only what moved: the same result, for a caller that frees a small region of a large
        garment (`untangle`; the kimono's re-wrap spent 3 of its 7.8 s of untangling tracking pinned vertices).
    """
    _check(model, state)
    if iterations < 0:
        raise InputError(f"iterations must be >= 0, got {iterations}")
    if collider is not None and not isinstance(collider, BodyCollider):
        raise InputError("collider must be a BodyCollider or None")
    p = model.params
    w = _work(model, state)
    stats = RelaxStats()
    c = state.contacts
    original = state.positions
    faces = _near_free(model, state) if around_free else state.face_active
    # The body is still and pinned vertices never move: after one full collision only the free ones need one.
    moved = None
    for _ in range(iterations):
        pos = state.positions
        K.reference_normals(
            pos,
            model.faces,
            model.face_adjacency,
            model.face_adjacency_sign,
            faces,
            p.unflip,
            w["normals"],
            w["ref"],
            w["flipped"],
        )
        K.shape_match_goals(pos, model.faces, model.rest_corners, w["ref"], faces, w["goals"])
        if p.bend_stiffness > 0 and len(model.hinges):
            K.hinge_deltas(pos, model.hinges, model.hinge_faces, faces, w["hinge"])
        K.gather_moves(
            pos,
            w["goals"],
            w["hinge"],
            model.vertex_corners_ptr,
            model.vertex_corners,
            model.vertex_hinges_ptr,
            model.vertex_hinges,
            faces,
            model.hinge_faces,
            state.pinned,
            c.face,
            c.distance,
            c.normal,
            p.stretch_stiffness,
            p.bend_stiffness if len(model.hinges) else 0.0,
            p.gravity_step_m,
            p.friction,
            p.contact_distance_m,
            p.max_step_m,
            w["out"],
            w["step"],
        )
        # Swap buffers: the new positions become the state's, the old array the next output.
        state.positions, w["out"] = w["out"], pos
        pos = state.positions
        if p.max_stretch is not None and p.gravity_step_m > 0:
            act = vertex_active(model, state)
            roots = state.pinned | (
                (c.face >= 0) & (c.distance < p.contact_distance_m) & (c.normal[:, 1] >= p.support_normal_y)
            )
            n = K.support_order(pos, roots, act, w["by_height"], w["order"], w["rank"])
            K.limit_strain(
                w["order"],
                n,
                w["rank"],
                act & ~state.pinned,
                model.adjacency_ptr,
                model.adjacency,
                model.adjacency_edge,
                model.rest_lengths,
                p.max_stretch,
                pos,
            )
        stats.iterations += 1
        stats.max_step_m = float(w["step"].max()) if len(w["step"]) else 0.0
        stats.flipped = int(w["flipped"][faces].sum())  # the others keep an older answer
        if collider is not None:
            stats.collision = collide(model, state, collider, moved=moved)
            stats.searches += stats.collision.searches
            if around_free and not collider.moving:
                moved = ~state.pinned
    if state.positions is not original:  # the buffers were swapped an odd number of times: copy back
        original[:] = state.positions
        w["out"], state.positions = state.positions, original
    return stats
