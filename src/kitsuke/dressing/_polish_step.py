"""The last step of every operation that leaves a garment on the body (wrap, re-wrap, drag release): a polish
(`kitsuke.cloth.polish_refined`: L-BFGS energy minimisation, strain capped, finer triangles where it folds), the
folds it leaves opened and the stretch that leaves limited (in turns, while the limit folds a triangle again), and
the result kept only where it is better than what the operation had.

Better means: its max edge strain is lower, no triangle is folded, its mean strain and largest stroke residual
are no worse than before or than issue 3's targets (1 %, 10 mm), whichever is larger, and layered cloth lies no
deeper on the wrong side of another layer than before or than the layer gap (2 mm). The polish is tried on a
copy, so a result that is not kept costs time, never quality.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..cloth import (
    BodyCollider,
    ClothModel,
    ClothState,
    RefinedPolish,
    Tethers,
    folded_faces,
    polish_refined,
    untangle,
)
from ..cloth._polish import cap_strain
from ..errors import InputError
from ..metrics import QualityTargets, layer_crossing_mm, strain

#: What the polish must not make worse than this, if it was better: the quality targets' mean strain and stroke
#: residual (metres).
POLISH_MEAN_STRAIN = QualityTargets().mean_strain
POLISH_RESIDUAL_M = 1e-3 * QualityTargets().stroke_residual_mm
#: Most turns of untangle then strain limit after the polish, while the limit folds a triangle again and each turn
#: leaves the opened cloth less strained than the last: opening the last folds can stretch the cloth round them (a
#: tiered skirt's 1.7 mm refined edge: 4.5 -> 11.4 % max strain), and the limit that takes that back can fold one
#: triangle, which the next turn opens.
UNFOLD_LIMIT_TURNS = 3


@dataclass(frozen=True)
class PolishSettings:
    """How to polish; see `kitsuke.cloth.polish_refined` (rounds 0: no polish; levels 0: the topology stays;
    strain_limit, limit_sweeps: its strain-limit sweeps). untangle_rounds, untangle_bend, untangle_iterations,
    untangle_rings : `kitsuke.cloth.untangle` after it (0 rounds: none; iterations None: its default); it presses
    the cloth round a fold flat, so it starts 1 ring round each. passes : most passes (the wrap's: a later one
    only while the max strain is over 5 %, from the better cloth the last one kept)."""

    rounds: int = 8
    iterations: int = 40
    levels: int = 0
    rings: int = 2
    refine_iterations: int = 80
    max_folds: int = 20
    strain_limit: float | None = 0.045
    limit_sweeps: int = 1000
    untangle_rounds: int = 10
    untangle_bend: float = 0.1
    untangle_iterations: int | None = None
    untangle_rings: int = 1
    passes: int = 1

    def __post_init__(self) -> None:
        counts = ("rounds", "levels", "rings", "max_folds", "limit_sweeps", "untangle_rounds", "passes")
        if any(getattr(self, name) < 0 for name in counts) or self.iterations < 1 or self.refine_iterations < 1:
            raise InputError(
                f"PolishSettings: {', '.join(counts)} >= 0, iterations and refine_iterations >= 1 required"
            )
        if self.strain_limit is not None and not 0.0 <= self.strain_limit < 1.0:
            raise InputError("PolishSettings.strain_limit must be a strain in [0, 1) or None")
        if not self.untangle_bend >= 0:
            raise InputError("PolishSettings.untangle_bend must be >= 0")


def is_better(
    model: ClothModel,
    before: ClothState,
    polished: ClothModel,
    after: ClothState,
    residual_of: Callable[[np.ndarray, RefinedPolish | None], np.ndarray] | None = None,
    body=None,
    refined: RefinedPolish | None = None,
) -> bool:
    """Keep the polished cloth `after` (of `polished`, refined or `model` itself) over `before` (of `model`)? (See
    the module docstring.) residual_of(positions, refined) -> (S,) stroke residuals, metres, of the cloth given
    (refined None) or of `refined`, the polish that made `after` (its refinement moves the stroke samples onto new
    faces); None: no strokes. body :
    the body (its vertices and faces) layered cloth's order is judged by (`kitsuke.metrics.wrong_side_mm`).
    (GarmentCode's shirt at 3 mm offset: the polish lowered the max 30 -> 11 % but folded three triangles, and
    opening them raised it to 34 %; its mean strain rose 0.8 -> 1.4 %.)"""
    sb = strain(before.positions, model.edges, model.rest_lengths)
    sa = strain(after.positions, polished.edges, polished.rest_lengths)
    ok = sa.max < sb.max and not folded_faces(polished, after).any() and sa.mean <= max(sb.mean, POLISH_MEAN_STRAIN)
    if ok and polished.face_layer is not None:
        # Layered cloth: no layer pushed through another (L-BFGS's long moves can carry a kimono's left front
        # through the right one beyond the reach where the layer planes hold it: 27 mm measured).
        crossed = layer_crossing_mm(after.positions, polished.faces, polished.face_layer, body)
        was = layer_crossing_mm(before.positions, model.faces, model.face_layer, body)
        ok = crossed <= max(was, 1e3 * polished.params.layer_gap_m)
    if ok and residual_of is not None:
        rb = residual_of(before.positions, None).max(initial=0.0)
        ra = residual_of(after.positions, refined).max(initial=0.0)
        ok = ra <= max(rb, POLISH_RESIDUAL_M)
    return bool(ok)


def polish_step(
    model: ClothModel,
    state: ClothState,
    collider: BodyCollider,
    settings: PolishSettings,
    *,
    tethers: Tethers | None = None,
    corner_data: dict[str, np.ndarray] | None = None,
    residual_of: Callable[[np.ndarray, RefinedPolish | None], np.ndarray] | None = None,
    level: np.ndarray | None = None,
    pending: np.ndarray | None = None,
) -> tuple[bool, RefinedPolish]:
    """Polish a copy of `state` (its pins held), open what it folded, and say whether to keep it (`is_better`).
    level, pending : the bookkeeping of an earlier refinement of this cloth (see `polish_refined`).
    Returns (kept, the RefinedPolish: its state is the polished copy, pins extended over new vertices as free)."""
    s = settings
    trial = state.copy()
    rp = polish_refined(
        model,
        trial,
        collider,
        rounds=s.rounds,
        iterations=s.iterations,
        levels=s.levels,
        rings=s.rings,
        refine_iterations=s.refine_iterations,
        max_folds=s.max_folds,
        strain_limit=s.strain_limit,
        limit_sweeps=s.limit_sweeps,
        tethers=tethers,
        corner_data=corner_data,
        level=level,
        pending=pending,
    )
    if s.untangle_rounds and folded_faces(rp.model, rp.state).any():
        extra = {} if s.untangle_iterations is None else {"iterations": s.untangle_iterations}
        best = None  # (max strain, state): the least strained unfolded cloth of the turns
        for _ in range(UNFOLD_LIMIT_TURNS):
            untangle(
                rp.model,
                rp.state,
                collider,
                rings=s.untangle_rings,
                rounds=s.untangle_rounds,
                bend_stiffness=s.untangle_bend,
                tethers=rp.tethers,
                **extra,
            )
            if s.strain_limit is None or not s.limit_sweeps:
                break
            gained = False  # a turn that leaves the opened cloth no less strained than an earlier one is the last
            if not folded_faces(rp.model, rp.state).any():
                worst = strain(rp.state.positions, rp.model.edges, rp.model.rest_lengths).max
                if best is None or worst < best[0]:
                    best, gained = (worst, rp.state.copy()), True
            # The cloth the untangle opened lies compressed or stretched again: limit it once more, and keep that
            # if it folds nothing; else open what the limit folded, and limit again.
            limited = rp.state.copy()
            cap_strain(rp.model, limited, collider, s.strain_limit, sweeps=s.limit_sweeps, tethers=rp.tethers)
            if not folded_faces(rp.model, limited).any():
                best = None
                rp.state = limited
                break
            if not gained:
                break
            rp.state = limited
        if best is not None:
            rp.state = best[1]
    return is_better(model, state, rp.model, rp.state, residual_of, collider, rp), rp
