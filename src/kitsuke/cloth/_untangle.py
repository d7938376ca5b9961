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
from ._tethers import Tethers

#: With tethers, a round's relaxing is cut into this many pieces with a tether projection after each, so the
#: relaxing smooths what the projection moved (measured on the T-shirt's wrap: max strain 35 % with one
#: projection after the round, 30 % with 3; 10 is no better).
TETHER_CHUNKS = 3
#: Most passes of the tether projection after each piece (it stops at a pass that moved nothing).
TETHER_PASSES = 10


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
#: Rounds of plain relaxing before a surviving fold is smoothed first (or half the rounds, if fewer). Later, the
#: region has grown so wide that 30 relax iterations no longer open it (measured after a 5 cm lift of the demo's
#: kimono: smoothing from round 5 left one armpit triangle folded after 10 rounds, from round 3 none after 8).
SMOOTH_AFTER = 3


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
    tethers: Tethers | None = None,
) -> UntangleStats:
    """Open folded triangles (in place on `state`): up to `rounds` times, relax (`iterations`, no gravity, with
    un-flipping and a hinge stiffness of `bend_stiffness`) only the vertices within `rings` rings of a folded
    triangle (one ring more each round); every other vertex, and every pinned one, stays exactly where it is.
    Stops when none is folded. tethers : cloth points kept within their reach (see `Tethers`), projected once
    after each round's relaxing, on the region's vertices only (measured on the T-shirt: the relaxing alone
    carried a back stroke 6 mm past its reach).
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
        if tethers is not None and len(tethers):
            # A tethered point half inside the region would move with it where its tether cannot follow (the
            # projection leaves points with a fixed vertex alone): free its whole triangle, and so on along the
            # stroke, whose triangles share vertices.
            while True:
                inside = free[tethers.tri]
                partial = inside.any(axis=1) & ~inside.all(axis=1) & ~pinned[tethers.tri].any(axis=1)
                if not partial.any():
                    break
                free[tethers.tri[partial].reshape(-1)] = True
        moved |= free
        if stats.rounds >= min(SMOOTH_AFTER, rounds // 2):  # relaxing alone did not open it: flatten it first
            _smooth(model, state.positions, grow_region(model.faces, seed, 1) & ~pinned, SMOOTH_PASSES)
        region = state.holding(~free)
        if tethers is None or not len(tethers):
            relax(local, region, collider, iterations=iterations, around_free=True)
        else:
            for chunk in np.array_split(np.arange(iterations), TETHER_CHUNKS):
                relax(local, region, collider, iterations=len(chunk), around_free=True)
                for _ in range(TETHER_PASSES):  # points sharing a vertex move each other: a few passes
                    if not tethers.project(state.positions, free):
                        break
        stats.rounds += 1
        folded = folded_faces(model, state)
    stats.after = int(folded.sum())
    stats.moved = int(moved.sum())
    return stats
