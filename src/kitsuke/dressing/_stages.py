"""The stages the wrap, the re-wrap and the drag's release are made of, with one signature:

    stats = stage(model, state, collider, config)      # in place on state.positions

model : the ClothModel (its params are the stage's cloth). state : a ClothState whose `pinned` are the pins this
stage holds, passed explicitly as a view (`ClothState.holding`): a stage never changes which vertices are pinned.
collider : the BodyCollider the stage collides with (the wrap shapes with the legs bridged for a skirt).
config : the stage's settings and inputs (a small frozen dataclass below). Returns a dict of what it did.

`run_stage` runs one, timed, announced to a progress callback, and checked for non-finite positions afterwards
(`ComputationError` naming the stage). `until_still` is the one loop that iterates a solver until its largest move
falls below a tolerance.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from ..cloth import (
    BodyCollider,
    ClothModel,
    ClothParams,
    ClothState,
    DynamicsParams,
    MovingBody,
    Tethers,
    dynamics_data,
    relax,
    restore_lengths,
    sew,
    step,
    untangle,
)
from ..errors import ComputationError
from ._grow import grow
from ._solve import GlobalRelax, gravity_settle
from .wrap_settings import CloseSettings, DrapeSettings, GrowSettings, LengthSettings, SettleSettings

Stage = Callable[[ClothModel, ClothState, BodyCollider, object], dict]


def until_still(step: Callable[[], float], iterations: int, tolerance_m: float) -> int:
    """Call `step` (it returns its largest vertex move, metres) up to `iterations` times, stopping after the first
    move below `tolerance_m`. Returns the number of steps taken."""
    for k in range(iterations):
        if step() < tolerance_m:
            return k + 1
    return iterations


def check_finite(state: ClothState, stage: str) -> None:
    """Raise ComputationError naming `stage` when a position is no longer finite."""
    if not np.isfinite(state.positions).all():
        n = int((~np.isfinite(state.positions).all(axis=1)).sum())
        raise ComputationError(stage, f"{n} cloth positions became non-finite")


@dataclass
class StageLog:
    """A pipeline's record: the operation's name (for errors), `say` called with a stage's name as it starts (a
    progress display), and seconds per stage (or per `timing` key), summed over repeats."""

    operation: str
    say: Callable[[str], None] = lambda _name: None
    timings: dict[str, float] = field(default_factory=dict)


def run_stage(
    log: StageLog,
    name: str,
    stage: Stage,
    model: ClothModel,
    state: ClothState,
    collider: BodyCollider,
    config: object,
    *,
    pinned: np.ndarray,
    timing: str | None = None,
) -> dict:
    """Run `stage` on `state` holding `pinned` (V,) bool; time it under `timing` (default: `name`), announce `name`
    to `log.say`, and raise ComputationError ("<operation>: <name>") if it leaves a position non-finite."""
    log.say(name)
    t0 = time.perf_counter()
    view = state.holding(pinned)
    out = stage(model, view, collider, config)
    if view.positions is not state.positions:  # a stage works in place: its view shares the state's arrays
        state.positions = view.positions
    key = timing or name
    log.timings[key] = log.timings.get(key, 0.0) + time.perf_counter() - t0
    check_finite(state, f"{log.operation}: {name}")
    return out


@dataclass(frozen=True)
class Growing:
    """grow_stage's config: the settings, the hang this garment grows with (`GrowSettings.hang`, or its
    `skirt_hang` round bridged legs) and the vertices `placed` (V,) bool to grow from."""

    settings: GrowSettings
    hang: float
    placed: np.ndarray


def grow_stage(model: ClothModel, state: ClothState, collider: BodyCollider, config: Growing) -> dict:
    """Grow the inactive triangles ring by ring from the placed vertices (`_grow.grow`), relaxing without gravity
    between rings; also the mend's regrowth."""
    s = config.settings
    rings = grow(
        model,
        state,
        config.placed.copy(),
        lambda _ring: relax(model, state, collider, iterations=s.iterations),
        rings_per_relax=s.rings_per_relax,
        hang=config.hang,
        hang_clearance_m=s.hang_clearance_m,
    )
    return {"rings": rings}


@dataclass(frozen=True)
class Closing:
    """close_stage's config: the settings, the vertices `held` (V,) bool pulled softly towards `targets`
    (V, 3) metres (where the strokes laid them), or None, and the crotch's height `legs_below_y` (metres; None: a
    body without two legs, or a garment round both, whose close sees them bridged as one). Below it the close's
    moves are swept (`GlobalRelax`'s `sweep_below_y`): a trouser's back panel laid behind a leg is not pulled
    through the knee to its front. Above it they are not: laid panels pass through the torso's side and the arm to
    where their seams close (a side seam at the armpit, a waistband's side at the hip), and are pushed out there."""

    settings: CloseSettings
    held: np.ndarray | None = None
    targets: np.ndarray | None = None
    legs_below_y: float | None = None


def close_stage(model: ClothModel, state: ClothState, collider: BodyCollider, config: Closing) -> dict:
    """The global relaxation without gravity (`_solve.GlobalRelax`, body contacts inside the solve) until still.
    A fresh solver each time: after a mend regrows cloth, contacts an earlier close had released must hold again.
    With `sew_frames`, sewing instead (`kitsuke.cloth.sew`), the stroke vertices held where the strokes put them."""
    s = config.settings
    if s.sew_frames:
        held = state.pinned if config.held is None else state.pinned | config.held
        stats = sew(model, state.holding(held), collider, shrink_m=s.sew_shrink_m, max_frames=s.sew_frames)
        return {"sewn_frames": stats.frames, "diverged": stats.diverged}
    solver = GlobalRelax(
        model,
        state.pinned,
        held=config.held,
        targets=config.targets,
        hold_weight=s.stroke_hold,
        contact_weight=s.contact_weight,
        cg_iterations=s.cg_iterations,
        sweep_below_y=config.legs_below_y,
    )
    return {"steps": until_still(lambda: solver.step(state, collider), s.iterations, s.tolerance_m)}


@dataclass(frozen=True)
class Settling:
    """settle_stage's config: the settings and the cloth (gravity, friction) of a Jacobi settle."""

    settings: SettleSettings
    cloth: ClothParams
    contact_weight: float


def settle_stage(model: ClothModel, state: ClothState, collider: BodyCollider, config: Settling) -> dict:
    """Gravity with collision: the paper's Jacobi relaxation, or global steps with static friction."""
    s = config.settings
    if s.iterations and s.method == "jacobi":
        relax(model.with_params(config.cloth), state, collider, iterations=s.iterations)
    elif s.iterations:
        gravity_settle(
            model,
            state,
            collider,
            state.pinned,
            iterations=s.iterations,
            gravity_m=s.gravity_m,
            stick_weight=s.stick_weight,
            contact_weight=config.contact_weight,
        )
    return {"iterations": s.iterations}


@dataclass(frozen=True)
class Draping:
    """drape_stage's config: the settings."""

    settings: DrapeSettings


#: The drape's steps per simulated second.
DRAPE_FPS = 30


def drape_stage(model: ClothModel, state: ClothState, collider: BodyCollider, config: Draping) -> dict:
    """Let the cloth hanging off the body fall under gravity (the dynamic solver), the cloth on the body held.
    Skipped when little cloth hangs. A step that diverges (`ComputationError`) puts the cloth back where the
    stage found it: the garment is then as the settle left it."""
    s = config.settings
    frames = int(round(s.seconds * DRAPE_FPS))
    if not frames or not model.n_vertices:
        return {"frames": 0}
    # A global query, not the tracked contacts: a skipped drape leaves the state exactly as it was.
    _, _, distance = collider.nearest(state.positions)
    hanging = float((distance >= s.hanging_m).mean())
    if hanging < s.min_hanging:
        return {"frames": 0, "hanging": round(hanging, 4)}
    held = state.pinned | (distance < s.hold_m)
    view = state.holding(held)
    before = state.positions.copy()
    params = DynamicsParams(damping=s.damping)
    data = dynamics_data(model, params)
    body = MovingBody.of(collider)
    try:
        for _ in range(frames):
            step(model, view, body, 1.0 / DRAPE_FPS, params, data)
    except ComputationError:
        state.positions[:] = before
        return {"frames": frames, "hanging": round(hanging, 4), "diverged": True}
    state.velocities = None
    return {"frames": frames, "hanging": round(hanging, 4), "held": int(held.sum())}


@dataclass(frozen=True)
class Finishing:
    """finish_stage's config: the length settings, the close's (for the optional global steps), the stroke
    tethers (or None), and whether every vertex's nearest body point is searched afresh before the sweeps."""

    lengths: LengthSettings
    close: CloseSettings
    tethers: Tethers | None = None
    search_afresh: bool = True


def finish_stage(model: ClothModel, state: ClothState, collider: BodyCollider, config: Finishing) -> dict:
    """Global steps without gravity (optional), then the edge-length sweeps with the tethers."""
    s = config.lengths
    out: dict = {"steps": 0}
    if s.finish_iterations:
        finish = GlobalRelax(model, state.pinned, contact_weight=config.close.contact_weight)
        out["steps"] = until_still(lambda: finish.step(state, collider), s.finish_iterations, config.close.tolerance_m)
    if s.sweeps:
        # The projection moves vertices along edges, across the body's surfaces where arm and torso meet: search
        # every vertex's nearest point afresh first (without it one shirt vertex ended 2.4 mm inside the torso).
        if config.search_afresh:
            state.contacts.forget()
        stats = restore_lengths(
            model,
            state,
            collider,
            sweeps=s.sweeps,
            tethers=config.tethers,
            over_relaxation=s.over_relaxation,
            chebyshev_rho=s.chebyshev_rho,
            collide_every=s.collide_every,
        )
        out["sweeps"], out["restarted"] = stats.sweeps, stats.restarted
    return out


@dataclass(frozen=True)
class Untangling:
    """untangle_stage's config: `kitsuke.cloth.untangle`'s rounds, hinge stiffness (None: its default), iterations
    (None: its default) and the stroke tethers (or None)."""

    rounds: int
    bend: float | None = None
    iterations: int | None = None
    tethers: Tethers | None = None


def untangle_stage(model: ClothModel, state: ClothState, collider: BodyCollider, config: Untangling) -> dict:
    """Open folded triangles by relaxing a few rings round them."""
    if not config.rounds:
        return {"rounds": 0}
    extra = {} if config.bend is None else {"bend_stiffness": config.bend}
    if config.iterations is not None:
        extra["iterations"] = config.iterations
    stats = untangle(model, state, collider, rounds=config.rounds, tethers=config.tethers, **extra)
    return {"rounds": stats.rounds, "folded_before": stats.before, "folded_after": stats.after}
