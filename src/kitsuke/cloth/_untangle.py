"""Untangling: open the triangles left folded over their neighbours, by relaxing only the cloth around them.

Why a separate step: the wrap's global relaxation and the settle both un-flip (ClothParams.unflip), but over the
whole garment a crumple of a few triangles is held shut by everything around it (measured on GarmentCode's hoody
on mean_all: 7 inverted triangles at the neckline after the wrap). Relaxing only a few rings of cloth around each
fold, the rest held still, with a stiffer hinge so that the fold opens instead of re-folding, removes them in
tens of iterations without moving the rest of the garment (hoody: 7 -> 0, the rest untouched).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from . import _kernels as K
from ._collide import BodyCollider
from ._model import ClothModel, ClothState
from ._relax import relax


@dataclass
class UntangleStats:
    """What `untangle` did. rounds : rounds run. before, after : folded triangles at the start and the end.
    moved : vertices that were free to move in some round."""

    rounds: int = 0
    before: int = 0
    after: int = 0
    moved: int = 0


def folded_faces(model: ClothModel, state: ClothState) -> np.ndarray:
    """(F,) bool: active triangles folded back over their neighbours, or collapsed (the relaxation's test)."""
    nf = model.n_faces
    normals, ref = np.zeros((nf, 3)), np.zeros((nf, 3))
    flipped = np.zeros(nf, dtype=np.uint8)
    K.reference_normals(
        state.positions,
        model.faces,
        model.face_adjacency,
        model.face_adjacency_sign,
        state.face_active,
        False,
        normals,
        ref,
        flipped,
    )
    return flipped.astype(bool)


#: Umbrella smoothing passes over a fold that a round of relaxation left shut.
SMOOTH_PASSES = 3


def _smooth(model: ClothModel, pos: np.ndarray, region: np.ndarray, passes: int) -> None:
    """Move each vertex of `region` (V,) bool to the mean of its edge neighbours, `passes` times (in place on
    pos (V, 3)). A fold pressed shut between two body parts (a kimono's armpit after a lift) stays shut under
    shape matching, whose goals are the folded triangles' own best fits; averaging with the neighbours takes the
    crease out of the geometry and lets the next relaxation start from an open surface."""
    e = model.edges
    idx = np.flatnonzero(region)
    if not len(idx):
        return
    deg = np.bincount(e.reshape(-1), minlength=len(pos)).astype(np.float64)
    for _ in range(passes):
        acc = np.zeros_like(pos)
        np.add.at(acc, e[:, 0], pos[e[:, 1]])
        np.add.at(acc, e[:, 1], pos[e[:, 0]])
        pos[idx] = acc[idx] / np.maximum(deg[idx], 1.0)[:, None]


def grow_region(faces: np.ndarray, vertices: np.ndarray, rings: int) -> np.ndarray:
    """(V,) bool: `vertices` (V,) bool and every vertex within `rings` triangle rings of them."""
    region = vertices.copy()
    for _ in range(rings):
        region[faces[region[faces].any(axis=1)].reshape(-1)] = True
    return region


def untangle(
    model: ClothModel,
    state: ClothState,
    collider: BodyCollider | None = None,
    *,
    rings: int = 3,
    iterations: int = 30,
    rounds: int = 10,
    bend_stiffness: float = 0.3,
) -> UntangleStats:
    """Open folded triangles (in place on `state`): up to `rounds` times, relax (`iterations`, no gravity, with
    un-flipping and a hinge stiffness of `bend_stiffness`) only the vertices within `rings` rings of a folded
    triangle (one ring more each round); every other vertex, and every pinned one, stays exactly where it is.
    Stops when none is folded.
    """
    state.check(model)
    if rings < 1 or iterations < 1 or rounds < 0 or not bend_stiffness >= 0:
        raise InputError("untangle needs rings >= 1, iterations >= 1, rounds >= 0 and bend_stiffness >= 0")
    local = model.with_params(
        dataclasses.replace(
            model.params, gravity_step_m=0.0, max_stretch=None, unflip=True, bend_stiffness=bend_stiffness
        )
    )
    stats = UntangleStats()
    folded = folded_faces(model, state)
    stats.before = int(folded.sum())
    moved = np.zeros(model.n_vertices, dtype=bool)
    pinned = state.pinned
    while folded.any() and stats.rounds < rounds:
        seed = np.zeros(model.n_vertices, dtype=bool)
        seed[model.faces[folded].reshape(-1)] = True
        # A fold that survives a round gets a wider region the next: what holds it shut may lie farther out.
        free = grow_region(model.faces, seed, rings + stats.rounds) & ~pinned
        moved |= free
        if stats.rounds >= rounds // 2:  # half the rounds of relaxing alone did not open it: flatten it first
            _smooth(model, state.positions, grow_region(model.faces, seed, 1) & ~pinned, SMOOTH_PASSES)
        state.pinned = ~free
        try:
            relax(local, state, collider, iterations=iterations)
        finally:
            state.pinned = pinned
        stats.rounds += 1
        folded = folded_faces(model, state)
    stats.after = int(folded.sum())
    stats.moved = int(moved.sum())
    return stats
