"""Edge-length restoration: Gauss-Seidel projection of every edge to its rest length, with collision.

Why besides `relax` and the wrap's global relaxation: both fit each triangle's rest shape and average the fits
per vertex (Jacobi) or in one least-squares solve, which takes out strain spread over many triangles but leaves
what is local: a row of edges stretched along a seam, a triangle squeezed where the cloth is pressed on the body.
Projecting edges one after another reaches those in a few hundred sweeps (measured after the wrap of
GarmentCode's shirt on mean_all: mean edge strain 1.43 % -> 0.95 % in 300 sweeps, 0.1 s; the wrap runs 400,
accelerated). It knows nothing of bending or folding: run `untangle` after it.

Chebyshev acceleration (Wang 2015, "A Chebyshev semi-iterative approach for accelerating projective and
position-based dynamics"): each accelerated sweep's result is extrapolated from the iterate two sweeps back,
q <- w_k (q_sweep - q_(k-1)) + q_(k-1), with the weights w_k of the Chebyshev polynomials for a sweep whose
error shrinks by `chebyshev_rho` per sweep. It carries a correction across the garment far faster than plain or
over-relaxed sweeps (measured on the shipped wrap cases: 400 accelerated sweeps end at a lower mean strain than
1200 over-relaxed ones).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ComputationError, InputError
from . import _kernels as K
from ._collide import BodyCollider, active_edge_index, collide, vertex_active
from ._model import ClothModel, ClothState
from ._tethers import Tethers

#: Sweeps at the end of `restore_lengths` that are never over-relaxed or accelerated.
PLAIN_FINISH = 100
#: Plain sweeps before the Chebyshev weights start (Wang 2015's delay: the first sweeps' error is not yet in the
#: slowly shrinking modes the weights are tuned for).
CHEBYSHEV_DELAY = 10


@dataclass
class LengthStats:
    """What `restore_lengths` did.

    sweeps : sweeps run. worst_error_m : the largest edge length error met in the last sweep, metres.
    searches : global nearest-point searches of the collision updates. worst_tether_m : the farthest a tethered
    point was beyond its reach in the last sweep, metres. restarted : the accelerated sweeps ran away (see
    `restore_lengths`) and were run again plain from the start.
    """

    sweeps: int = 0
    worst_error_m: float = 0.0
    worst_tether_m: float = 0.0
    searches: int = 0
    restarted: bool = False


def restore_lengths(
    model: ClothModel,
    state: ClothState,
    collider: BodyCollider | None = None,
    *,
    sweeps: int = 300,
    collide_every: int = 3,
    tolerance_m: float = 0.0,
    tethers: Tethers | None = None,
    over_relaxation: float = 1.0,
    chebyshev_rho: float | None = None,
    band: float = 0.0,
    search_first: bool = False,
) -> LengthStats:
    """Pull every edge of the active triangles towards its rest length (in place on `state`).

    sweeps : Gauss-Seidel sweeps over the edges, alternately forwards and backwards (a one-way order would drift
        the cloth towards where the sweep ends). collide_every : a collision update after this many sweeps and
        after the last (the projection moves vertices by at most a few millimetres per sweep, so collision need
        not follow each one; measured on the shirt: every sweep or every third, the same strain).
    tolerance_m : stop once no edge is further than this from its rest length and no tethered point further than
        this beyond its reach, metres (0: stop only at a sweep that found nothing to correct).
    tethers : cloth points kept within a reach of polylines, projected after the edges in every sweep, so the
        edges settle around them (the wrap keeps its pattern strokes near their body strokes this way).
    over_relaxation : omega of successive over-relaxation, 1 <= omega < 2: each edge is moved omega times the
        way to its rest length, which carries a correction across the garment in fewer sweeps; the last
        PLAIN_FINISH sweeps are plain (omega 1), so the edges end at rest rather than overshooting it (measured
        after the shirt's wrap at 1.5: 1.26 % mean strain without them, 0.75 % with 20-200).
    chebyshev_rho : None (no acceleration) or the estimated spectral radius of one sweep, 0 < rho < 1: the sweeps
        between the first CHEBYSHEV_DELAY and the last PLAIN_FINISH are Chebyshev-accelerated (module
        docstring). Too large a rho overshoots: measured on the shipped wrap cases, 0.99 lowers the strain
        everywhere, 0.995 raises the T-shirt's max strain 12 -> 23 %.
    band : a strain, >= 0: edges within band * rest of their rest length are left alone and the others pulled
        only to the nearer end of the band (a strain limit: the wrap's last step caps what the polish left over
        4.5 % this way without pressing the buckles it found flat). 0: every edge to its rest length.
    The last collision update searches every vertex's nearest body point afresh (`Contacts.forget`): the walk
    can leave a vertex pushed into the torso at an armpit tracked to the arm, outside it (measured on the shirt's
    wrap: 7 vertices up to 3.5 mm inside after 400 accelerated sweeps without it, none with it).
    search_first : search afresh before the first sweep instead (with a collider), so the sweeps correct what
        that search's push did: a strain limit after a polish whose cloth already lies where the walk found it
        (the fresh search pushes the cloth pinched in an armpit 1-2 mm off the other side: GarmentCode's hoody
        4.5 -> 6.0 % max strain when it comes last).
    Pinned vertices, and vertices of no active triangle, do not move.
    """
    if not isinstance(state, ClothState):
        raise InputError("restore_lengths needs a ClothModel and a ClothState")
    state.check(model)
    if sweeps < 0 or collide_every < 1 or not tolerance_m >= 0 or not 1.0 <= over_relaxation < 2.0:
        raise InputError(
            "restore_lengths needs sweeps >= 0, collide_every >= 1, tolerance_m >= 0 and 1 <= over_relaxation < 2"
        )
    if not 0.0 <= band < 1.0:
        raise InputError(f"restore_lengths needs 0 <= band < 1, got {band}")
    if chebyshev_rho is not None and not 0.0 < chebyshev_rho < 1.0:
        raise InputError(f"restore_lengths needs 0 < chebyshev_rho < 1 (or None), got {chebyshev_rho}")
    if collider is not None and not isinstance(collider, BodyCollider):
        raise InputError("collider must be a BodyCollider or None")
    if tethers is not None and not isinstance(tethers, Tethers):
        raise InputError("tethers must be a kitsuke.cloth.Tethers or None")
    if tethers is not None and len(tethers) and tethers.tri.max() >= model.n_vertices:
        raise InputError("tethers name cloth vertices the model does not have")
    start_positions = state.positions.copy()

    def sweep(omega: float, rho: float | None) -> LengthStats | None:
        return _sweep(
            model, state, collider, sweeps, collide_every, tolerance_m, tethers, omega, rho, band, search_first
        )

    stats = sweep(over_relaxation, chebyshev_rho)
    if stats is None:  # ran away: again from the start, neither accelerated nor over-relaxed
        state.positions[:] = start_positions
        state.contacts.forget()
        stats = sweep(1.0, None)
        if stats is None:
            raise ComputationError("length restoration", "edge projection ran away (non-finite or metres of motion)")
        stats.restarted = True
    return stats


#: Sweeps that move any vertex farther than this from where they started ran away (metres; a wrap's length
#: restoration moves cloth millimetres to a few centimetres).
RUNAWAY_M = 0.5
#: ... or whose worst edge error grows past this many times the largest seen in the first sweeps (at least 1 cm).
RUNAWAY_GROWTH = 10.0


def _sweep(
    model,
    state,
    collider,
    sweeps,
    collide_every,
    tolerance_m,
    tethers,
    over_relaxation,
    chebyshev_rho,
    band,
    search_first,
) -> LengthStats | None:
    """The sweeps of `restore_lengths`; None when they run away (Chebyshev extrapolation fighting tethers or pins
    can grow without bound: GarmentCode's shirt on strokes drawn from its placement reached 1e18 m): a
    non-finite position, a vertex RUNAWAY_M from its start, or an edge error RUNAWAY_GROWTH times the first
    sweeps' worst."""
    movable = vertex_active(model, state) & ~state.pinned
    forward = active_edge_index(model, state)
    forward = forward[movable[model.edges[forward]].any(axis=1)]  # an edge with both ends held cannot move
    backward = np.ascontiguousarray(forward[::-1])
    stats = LengthStats()
    pos = state.positions
    if search_first and collider is not None:
        state.contacts.forget()
        stats.searches += collide(model, state, collider).searches
    accelerate = chebyshev_rho is not None and sweeps > PLAIN_FINISH + CHEBYSHEV_DELAY
    # A strain limit (band, plain sweeps) meets only the edges and tether points whose vertices moved since they
    # were last met (`K.project_band`): the same sweeps, most of each skipped.
    stamps = None
    if band > 0.0 and not accelerate and over_relaxation == 1.0:
        clock = np.zeros(1, dtype=np.int64)
        moved, seen = np.zeros(model.n_vertices, dtype=np.int64), np.full(model.n_edges, -1, dtype=np.int64)
        stamps = (moved, np.full(len(tethers) if tethers is not None else 0, -1, dtype=np.int64), clock)
        collided = -1  # the clock at the last collision (none yet: every vertex counts as moved)
    if accelerate:
        older, start = pos.copy(), np.empty_like(pos)  # the iterates one and two sweeps back
        rho2, weight = chebyshev_rho * chebyshev_rho, 1.0
    origin, first_worst = pos.copy(), 0.0
    for s in range(sweeps):
        plain = s >= sweeps - PLAIN_FINISH
        if accelerate:
            np.copyto(start, pos)
        order = backward if s % 2 else forward
        if stamps is not None:
            stats.worst_error_m = float(
                K.project_band(pos, model.edges, model.rest_lengths, movable, order, band, moved, seen, clock)
            )
        else:
            stats.worst_error_m = float(
                K.project_lengths(
                    pos, model.edges, model.rest_lengths, movable, order, 1.0 if plain else over_relaxation, band
                )
            )
        if tethers is not None and len(tethers):
            stats.worst_tether_m = tethers.project(pos, movable, stamps)
        if accelerate and not plain and s >= CHEBYSHEV_DELAY:
            weight = 2.0 / (2.0 - rho2) if s == CHEBYSHEV_DELAY else 4.0 / (4.0 - rho2 * weight)
            pos -= older  # pinned and inactive vertices: q_sweep = q_(k-1), so they stay where they are
            pos *= weight
            pos += older
        if accelerate:
            older, start = start, older
        stats.sweeps += 1
        if s < CHEBYSHEV_DELAY:
            first_worst = max(first_worst, stats.worst_error_m)
        elif not stats.worst_error_m <= RUNAWAY_GROWTH * max(first_worst, 0.01) or (
            s % 16 == 0 and not _bounded(pos, origin)
        ):
            return None
        last = s == sweeps - 1 or max(stats.worst_error_m, stats.worst_tether_m) <= tolerance_m
        if collider is not None and ((s + 1) % collide_every == 0 or last):
            forgot = last and not search_first
            if forgot:
                state.contacts.forget()
            if stamps is None or forgot:
                stats.searches += collide(model, state, collider).searches
            else:  # only what moved since the last collision is tracked; what the collision moves is met again
                before = pos.copy()
                stats.searches += collide(model, state, collider, moved=moved > collided).searches
                clock[0] += 1
                moved[(pos != before).any(axis=1)] = clock[0]
                collided = clock[0] - 1
        if last:
            break
    if not _bounded(pos, origin):
        return None
    return stats


def _bounded(pos: np.ndarray, origin: np.ndarray) -> bool:
    """Every position finite and within RUNAWAY_M of where it started."""
    d = pos - origin
    worst = float(np.einsum("ij,ij->i", d, d).max(initial=0.0))
    return bool(np.isfinite(worst) and worst <= RUNAWAY_M * RUNAWAY_M)


def compile_lengths() -> None:
    """Compile the length sweeps' and the tethers' kernels (`project_lengths`, `project_band`, `project_tethers`
    with and without stamps), or load them from numba's cache, on a small stretched sheet with one tether: the
    argument types the wrap passes them. A cold `kitsuke demo` compiled them in its own process for 2.3 s after
    its relaxation's kernels; `kitsuke.cloth.precompile_in_background` runs this in another process instead."""
    from ._shapes import grid_sheet

    uv, faces = grid_sheet(3, 3, 0.02)
    model = ClothModel.from_flat(faces, uv)
    tethers = Tethers.from_polylines([(np.array([0]), np.full((1, 3), 1 / 3), np.zeros((2, 3)))], faces, 0.01)
    for band in (0.0, 0.045):  # a restoration, then a strain limit (stamped sweeps)
        state = ClothState.new(model, np.c_[1.1 * uv, np.zeros(len(uv))])
        restore_lengths(model, state, sweeps=2, tethers=tethers, band=band)
