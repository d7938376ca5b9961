"""Polish: minimise an energy that caps edge strain, letting excess cloth buckle instead of staying compressed.

Why besides the relaxation and the length sweeps: both move vertices towards rest shapes one small step at a
time, so cloth with more length than the body has room for stays pressed flat and compressed (the pattern's ease,
a hood gathered at the neck), and cloth pulled between two contacts stays stretched. A quasi-Newton method
(L-BFGS) on one energy over the whole garment finds the buckles: out of plane, a wrinkle costs only bending.

The energy, per round, with the body's contact planes and the stroke tethers' nearest points held fixed:

- stretch: sum over edges of L (STRETCH_WEIGHT s^2 + LIMIT_WEIGHT max(|s| - LIMIT_STRAIN, 0)^2), s = l / L - 1
  (L the rest length): a quadratic spring and, past LIMIT_STRAIN, a stiffer barrier on top;
- bending: BEND_WEIGHT times the quadratic bending energy (Bergou et al. 2006, "A quadratic bending model for
  inextensible surfaces"; `bending_stencil`): per hinge, the cotangent-weighted combination of its four vertices
  that vanishes while the hinge is flat, squared;
- contact: CONTACT_WEIGHT max(offset - (x - p) . n, 0)^2 per vertex near the body (p, n its tracked body point
  and normal, offset `ClothParams.contact_offset_m`);
- tethers: TETHER_WEIGHT max(|x - q| - reach, 0)^2 per tethered cloth point, q its nearest polyline point;
- layers (layered cloth): LAYER_WEIGHT max(gap - (x - q) . n, 0)^2 per vertex over or under another layer, q its
  nearest point there (moving with that face) and n the way it must lie (`layer_planes`).

Each round is one call of a compiled L-BFGS (`_lbfgs.minimise`) over the compiled energy (`_polish_energy`), built
from the terms that touch a moving vertex only. Between rounds the collision runs (fresh contacts, layers kept)
and hinges round triangles folded over their neighbours get STIFFEN times their bending weight (up to
STIFFEN_MAX): a crease the energy found cheap is opened into a rounder buckle (measured on the FreeSewing T-shirt
after the wrap: 3 folded triangles without it, 0 with).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ._collide import BodyCollider, collide, layer_planes, vertex_active
from ._lbfgs import minimise
from ._lengths import restore_lengths
from ._model import ClothModel, ClothState
from ._polish_energy import bending_stencil
from ._subdivide import refine
from ._tethers import Tethers
from ._untangle import folded_faces, grow_region

#: Weight of the edge spring (per metre of rest length). With LIMIT_WEIGHT it sets how strain is shared: weaker
#: springs let the mean strain rise (GarmentCode's shirt polished and refined: 0.99 / 0.85 / 0.76 % at 100 / 300 /
#: 1000; before the refinement 1.8 % at 1, 1.3 % at 20).
STRETCH_WEIGHT = 1000.0
#: Weight of the barrier past LIMIT_STRAIN, on top of the spring: edges past it cost four times as much per unit
#: of strain squared. (The strain limit after the polish, not this barrier, keeps edges under 4.5 %; but the
#: nearer the polish comes, the fewer sweeps the limit needs: GarmentCode's shirt, stretched over the shoulder
#: points, at 1000: 6.1 % after 100 sweeps, 5.2 % after 800; at 3000: 5.2 and 4.7 %; at 10000: 4.9 and 4.6 %, but
#: mean strain 0.75 -> 0.86 %.)
LIMIT_WEIGHT = 3000.0
#: Strain where the barrier starts, below the issue's 5 % so that the barrier's own give stays under it.
LIMIT_STRAIN = 0.02
#: Bending weight (metres of rest length): small, a wrinkle must be cheaper than compression. 1e-3 raised the
#: hoody's mean strain 0.86 -> 1.03 %; 1e-2 kept its crumple compressed (max 6.4 %).
BEND_WEIGHT = 1e-4
#: Contact penalty weight: stiff enough that the collision after a round moves vertices by fractions of a mm.
CONTACT_WEIGHT = 1e6
#: Tether penalty weight.
TETHER_WEIGHT = 1e6
#: Layer order penalty weight (layered cloth: each vertex over or under another layer kept on its side, the
#: `layer_planes` of the round's start; without it the kimono's fronts crossed by up to 28 mm).
LAYER_WEIGHT = 1e6
#: A vertex nearer the body than this (metres) gets a contact plane for the round.
CONTACT_REACH_M = 0.01
#: Bending weight factor per round on the hinges within STIFFEN_RINGS rings of a folded triangle, and its cap
#: (measured on the T-shirt: factor 10 with no cap left 0 folded but 9 % max strain; 3 up to 30: 0 and 4 %).
STIFFEN = 3.0
STIFFEN_MAX = 30.0
STIFFEN_RINGS = 2
#: L-BFGS memory (correction pairs).
LBFGS_MEMORY = 20
#: After a refinement level, the polish moves the refined cloth and this many rings of cloth round it.
LOCAL_RINGS = 3
#: The strain limit's sweeps (`polish_refined`): a collision update after this many, and a stop once no edge is
#: farther than LIMIT_TOLERANCE_M (metres: rounding) beyond the limit.
LIMIT_COLLIDE_EVERY = 8
LIMIT_TOLERANCE_M = 1e-7
#: A strain limit (`cap_strain`) is undone when it leaves the max edge strain more than this above what it was, or
#: the mean more than LIMIT_KEEP_MEAN above (a fifth of the 1 % mean target): it made the cloth worse. On the
#: shipped cases it never does (it takes the shirt's max 10.5 -> 5.0 % for +0.09 points of mean strain).
LIMIT_KEEP_MAX = 0.005
LIMIT_KEEP_MEAN = 0.002
#: Most strain-limit sweeps after each polish but the last (`polish_refined`).
LIMIT_SWEEPS_BETWEEN = 400


@dataclass
class PolishStats:
    """What `polish` did. rounds : rounds run. iterations : L-BFGS iterations in all. energy : the energy at the
    end of the last round. folded : triangles folded over their neighbours at the end (see `untangle`)."""

    rounds: int = 0
    iterations: int = 0
    energy: float = 0.0
    folded: int = 0


def energy_terms(
    edges, rest, hinges, bend_w, bend_coef, near, points, normals, offset, layer_v, layer_tri, layer_b, layer_n,
    layer_gap, tether_tri, tether_bary, targets, reach,
) -> tuple:  # fmt: skip
    """The argument tuple of `polish_energy` (and `minimise`): the arrays with the module's weights between them.
    One place builds it, so `compile_polish` compiles the very signature `polish` calls."""
    return (
        edges, rest, STRETCH_WEIGHT, LIMIT_WEIGHT, LIMIT_STRAIN,
        hinges, bend_w, bend_coef,
        near, points, normals, float(offset), CONTACT_WEIGHT,
        layer_v, layer_tri, layer_b, layer_n, float(layer_gap), LAYER_WEIGHT,
        tether_tri, tether_bary, targets, float(reach), TETHER_WEIGHT,
    )  # fmt: skip


def compile_polish() -> None:
    """Compile the polish's L-BFGS and energy (`minimise`), or load them from numba's cache, on a one-triangle
    sheet: the same argument types as `polish` (`energy_terms`). The longest compile of a wrap (7-8 s of a cold
    `kitsuke dress`); `kitsuke.cloth.precompile_in_background` runs this in another process while the wrap
    compiles and runs its earlier stages."""
    i3, f3 = np.zeros((0, 3), dtype=np.int64), np.zeros((0, 3))
    x = np.array([[0.0, 0.0, 0.0], [0.01, 0.0, 0.0], [0.0, 0.01, 0.0]])
    terms = energy_terms(
        np.array([[0, 1], [1, 2], [0, 2]], dtype=np.int64), np.full(3, 0.01),
        np.zeros((0, 4), dtype=np.int64), np.zeros((0, 4)), np.zeros(0),
        np.zeros(0, dtype=np.int64), f3, f3, 0.001,
        np.zeros(0, dtype=np.int64), i3, f3, f3, 0.002,
        i3, f3, f3, 0.0,
    )  # fmt: skip
    minimise(x, np.arange(3, dtype=np.int64), 1, LBFGS_MEMORY, terms)


def polish(
    model: ClothModel,
    state: ClothState,
    collider: BodyCollider,
    *,
    rounds: int = 20,
    iterations: int = 40,
    tethers: Tethers | None = None,
) -> PolishStats:
    """Minimise the module's energy (in place on `state`): `rounds` rounds of up to `iterations` L-BFGS
    iterations, each round with fresh contact planes and tether targets and a collision update before it and
    after the last. Pinned vertices and vertices without an active triangle stay where they are.

    It may leave triangles folded (a crease the energy found cheap): run `untangle` after it.
    """
    state.check(model)
    if rounds < 0 or iterations < 1:
        raise InputError("polish needs rounds >= 0 and iterations >= 1")
    if not isinstance(collider, BodyCollider):
        raise InputError("collider must be a BodyCollider")
    stats = PolishStats()
    if not rounds:
        return stats
    offset, layer_gap = model.params.contact_offset_m, model.params.layer_gap_m
    moving = vertex_active(model, state) & ~state.pinned
    free = np.flatnonzero(moving)
    # Only the terms that touch a moving vertex: the rest are constant (a local polish after a refinement moves a
    # tenth of the garment; its energy over the whole garment made it four times slower).
    local_edges = moving[model.edges].any(axis=1)
    edges, rest = np.ascontiguousarray(model.edges[local_edges]), model.rest_lengths[local_edges]
    local_hinges = moving[model.hinges].any(axis=1)
    hinges = np.ascontiguousarray(model.hinges[local_hinges])
    bend_w, bend_coef = bending_stencil(model)
    bend_w, bend_coef = bend_w[local_hinges], BEND_WEIGHT * bend_coef[local_hinges]
    hinge_weight = np.ones(len(hinges))
    tether_tri, tether_bary, reach = np.zeros((0, 3), dtype=np.int64), np.zeros((0, 3)), 0.0
    if tethers is not None and len(tethers):
        tethered = moving[tethers.tri].any(axis=1)
        tether_tri = np.ascontiguousarray(tethers.tri[tethered], dtype=np.int64)
        tether_bary, reach = np.ascontiguousarray(tethers.bary[tethered]), float(tethers.reach_m)
    for r in range(rounds):
        collide(model, state, collider)
        if r:
            folded = folded_faces(model, state)
            if folded.any():
                near_fold = np.zeros(model.n_vertices, dtype=bool)
                near_fold[model.faces[folded].reshape(-1)] = True
                near_fold = grow_region(model.faces, near_fold, STIFFEN_RINGS)
                grown = near_fold[hinges].any(axis=1)
                hinge_weight[grown] = np.minimum(hinge_weight[grown] * STIFFEN, STIFFEN_MAX)
        c = state.contacts
        near = np.flatnonzero((c.face >= 0) & (c.distance < CONTACT_REACH_M) & moving)
        layers = layer_planes(model, state)
        layer_tri = np.ascontiguousarray(model.faces[layers.face])
        mine = moving[layers.vertex] | moving[layer_tri].any(axis=1)
        layer_v, layer_tri = np.ascontiguousarray(layers.vertex[mine]), np.ascontiguousarray(layer_tri[mine])
        layer_b, layer_n = np.ascontiguousarray(layers.bary[mine]), np.ascontiguousarray(layers.normal[mine])
        points, normals = np.ascontiguousarray(c.point[near]), np.ascontiguousarray(c.normal[near])
        targets = np.zeros((0, 3))
        if tethers is not None and len(tethers):
            targets = np.ascontiguousarray(tethers.nearest(state.positions)[tethered])
        terms = energy_terms(
            edges, rest, hinges, bend_w, np.ascontiguousarray(bend_coef * hinge_weight),
            near, points, normals, offset, layer_v, layer_tri, layer_b, layer_n, layer_gap,
            tether_tri, tether_bary, targets, reach,
        )  # fmt: skip
        energy, done, _ = minimise(state.positions, free, iterations, LBFGS_MEMORY, terms)
        stats.iterations += int(done)
        stats.energy = float(energy)
        stats.rounds += 1
    collide(model, state, collider)
    stats.folded = int(folded_faces(model, state).sum())
    return stats


def cap_strain(
    model: ClothModel,
    state: ClothState,
    collider: BodyCollider,
    limit: float,
    *,
    sweeps: int = 1000,
    tethers: Tethers | None = None,
) -> bool:
    """Pull every edge strained more than `limit` back to it, leaving the others alone (in place): up to `sweeps`
    Gauss-Seidel sweeps of `restore_lengths` with that band, the body searched afresh before the first (so the
    sweeps correct what the search's push does), collision every LIMIT_COLLIDE_EVERY sweeps, the tethers held;
    they stop once nothing is farther than LIMIT_TOLERANCE_M beyond the band.

    Where the body will not let the limit have its way (cloth pinched between an arm and the torso, pushed back by
    the collision after every few sweeps), the sweeps spread the strain instead of removing it: on a GarmentCode
    top, max strain 29 -> 43 % and mean 0.93 -> 1.36 % in one call. Such a result is undone: the cloth goes back to
    where it was unless its max strain is no more than LIMIT_KEEP_MAX above what it was and its mean strain no more
    than LIMIT_KEEP_MEAN above. Returns whether the limited cloth was kept."""
    max0, mean0 = _strain_max_mean(model, state.positions)
    saved = state.copy()
    restore_lengths(
        model,
        state,
        collider,
        sweeps=sweeps,
        band=limit,
        tethers=tethers,
        collide_every=LIMIT_COLLIDE_EVERY,
        tolerance_m=LIMIT_TOLERANCE_M,
        search_first=True,
    )
    max1, mean1 = _strain_max_mean(model, state.positions)
    if max1 <= max0 + LIMIT_KEEP_MAX and mean1 <= mean0 + LIMIT_KEEP_MEAN:
        return True
    state.positions[:] = saved.positions
    state.contacts.assign(saved.contacts)
    return False


def _strain_max_mean(model: ClothModel, positions: np.ndarray) -> tuple[float, float]:
    """The largest and the mean edge strain |length / rest − 1| of the cloth at `positions`."""
    e = model.edges
    r = np.abs(np.linalg.norm(positions[e[:, 0]] - positions[e[:, 1]], axis=1) / model.rest_lengths - 1.0)
    return (float(r.max()), float(r.mean())) if len(r) else (0.0, 0.0)


@dataclass
class RefinedPolish:
    """What `polish_refined` made: the cloth after the polish, finer where it had folded.

    model, state : the refined cloth (old vertices keep their indices, new ones follow; the faces are new).
    parent_face : (F',) int64, the face of the input model each face came from (it lies in it or, made by an edge
    flip, partly in the face across that edge; never in another piece: seams do not flip). corner_data : the
    per-corner attributes given, carried onto the new faces. levels : refinement steps run (a face is split at
    most `refine`'s max_level times in all).
    stats : the first polish's PolishStats, with the later polishes' rounds and iterations added (energy and
    folded: the last polish's). level, pending : the refinement's bookkeeping per face (`Refinement.level`,
    `.pending`), None if nothing was refined: pass them to a later `polish_refined` of the same cloth.
    tethers : the tethers given, moved onto the refined faces (`Tethers.refined`), or None.
    """

    model: ClothModel
    state: ClothState
    parent_face: np.ndarray
    corner_data: dict[str, np.ndarray]
    levels: int
    stats: PolishStats
    level: np.ndarray | None = None
    pending: np.ndarray | None = None
    tethers: Tethers | None = None


def polish_refined(
    model: ClothModel,
    state: ClothState,
    collider: BodyCollider,
    *,
    rounds: int = 8,
    iterations: int = 40,
    levels: int = 3,
    rings: int = 2,
    refine_iterations: int = 80,
    strain_limit: float | None = None,
    limit_sweeps: int = 400,
    tethers: Tethers | None = None,
    corner_data: dict[str, np.ndarray] | None = None,
    max_folds: int = 20,
    level: np.ndarray | None = None,
    pending: np.ndarray | None = None,
) -> RefinedPolish:
    """`polish`, then, while triangles are left folded, up to `levels` adaptive sqrt(3) steps (`refine`) on the
    faces within `rings` rings of the folds, each followed by a polish of `rounds` rounds of up to
    `refine_iterations` L-BFGS iterations. `state` is polished in place until the first refinement; the cloth at
    the end (refined or not) is the one returned.

    Why: at 1.5 cm edges the cloth the body has no room for (a hood gathered at the neck) buckles into creases
    of a triangle or two, folded over their neighbours; opening them (`untangle`) presses the cloth flat again
    and brings the compression back. Triangles a third and a ninth the size round the same buckle into a wrinkle
    that folds nothing (GarmentCode's hoody on mean_all: 9 folded triangles and 5.9 % max strain after the
    polish; 0 folded and 4.5 % after three levels, 6,300 -> 6,700 faces).

    strain_limit : a strain (e.g. 0.045) or None. After each polish, up to LIMIT_SWEEPS_BETWEEN (after the last
        one `limit_sweeps`) Gauss-Seidel sweeps pull
        every edge strained more than this back to it and leave the others alone (`restore_lengths` with a band,
        searching the body afresh first, the tethers held): the polish's barrier is soft (a stiffer one stalls
        L-BFGS) and this takes the few edges it left over the limit under it without the equal-length sweeps'
        flattening of its buckles. The folds looked for are those left after it.
    level, pending : a previous `polish_refined`'s RefinedPolish.level / .pending of this cloth, so that its faces
        are not split past `refine`'s max_level nor its pending flips lost (None: unrefined cloth).
    max_folds : refine only while at most this many triangles are folded: refinement rounds off a few creases;
        cloth crumpled in many places is left to the untangle (measured on the demo kimono, 36 folds after the
        polish, most in its hanging sleeves and skirt: five levels of refinement there ended at 465 % max strain).
    Tether points keep the corners they were given on (old vertices keep their indices), so `tethers` hold on
    the refined cloth as they did. corner_data : {name: (F, 3, ...) array} carried like the rest corners.
    """
    if levels < 0 or rings < 0 or refine_iterations < 1 or limit_sweeps < 0 or max_folds < 0:
        raise InputError(
            "polish_refined needs levels >= 0, rings >= 0, refine_iterations >= 1, limit_sweeps >= 0, max_folds >= 0"
        )
    if strain_limit is not None and not 0.0 <= strain_limit < 1.0:
        raise InputError(f"polish_refined needs a strain_limit in [0, 1) or None, got {strain_limit}")

    def limit(model: ClothModel, state: ClothState, sweeps: int) -> None:
        if strain_limit is not None and sweeps:
            cap_strain(model, state, collider, strain_limit, sweeps=sweeps, tethers=tethers)

    # Between levels the limit only needs to show where it folds the cloth; the full count ends the last one.
    between = min(limit_sweeps, LIMIT_SWEEPS_BETWEEN)
    stats = polish(model, state, collider, rounds=rounds, iterations=iterations, tethers=tethers)
    limit(model, state, between)
    parent = np.arange(model.n_faces, dtype=np.int64)
    carried = {k: np.asarray(v) for k, v in (corner_data or {}).items()}
    done = 0
    for _ in range(levels):
        folded = folded_faces(model, state)
        if not folded.any() or folded.sum() > max_folds:
            break
        near = np.zeros(model.n_vertices, dtype=bool)
        near[model.faces[folded].reshape(-1)] = True
        near = grow_region(model.faces, near, rings)
        select = near[model.faces].all(axis=1) & state.face_active
        before = model
        model, state, r = refine(
            model, state, collider, select=select, level=level, pending=pending, corner_data=carried
        )
        if tethers is not None:
            tethers = tethers.refined(before, model, r.parent_face)
        level, pending, carried = r.level, r.pending, r.corner_data
        parent = parent[r.parent_face]
        done += 1
        # The rest of the garment has been polished and limited: only the refined cloth and LOCAL_RINGS rings round
        # it move.
        local = np.concatenate([near, np.ones(model.n_vertices - len(near), dtype=bool)])
        local = grow_region(model.faces, local, LOCAL_RINGS)
        around = state.holding(state.pinned | ~local)
        more = polish(model, around, collider, rounds=rounds, iterations=refine_iterations, tethers=tethers)
        limit(model, around, between)
        stats.rounds += more.rounds
        stats.iterations += more.iterations
        stats.energy, stats.folded = more.energy, more.folded
    if limit_sweeps > between:
        limit(model, state, limit_sweeps)
    return RefinedPolish(model, state, parent, carried, done, stats, level, pending, tethers)
