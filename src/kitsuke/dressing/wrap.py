"""The wrap (SPEC §4.2): put a sewing pattern on a body from corresponding strokes.

    from kitsuke.dressing import wrap, WrapParams
    garment = wrap(body, pattern, strokes)                    # DressedGarment
    garment.report.ok, garment.stroke_residual_m, garment.timings

Steps (the paper's, with the interpretations of SPEC §4.2):

1. **Transfer** (`_place`): the pattern triangles each pattern stroke crosses are laid on the body along its body
   stroke, at the cloth's own length with the middles together (the body stroke continued straight past its ends
   where it is shorter; offsets across the stroke laid out on the surface; `lift_m` off it), the body stroke
   taken the way round the placement or the pattern's up says.
2. **Growth** (`_grow`): the rest of the garment grows ring by ring from the placed triangles, each new triangle
   unfolded from its placed neighbour (from the cloth, not the body), with relaxation and collision between rings.
   The stroke triangles stay pinned while the garment grows.
3. **Seams**: the garment mesh shares the vertices of every seam from the start (`_weld`; corners where two seams
   of one piece meet are repaired first, `repair_corners`), so where two grown regions meet at a seam the
   triangles between them are stretched. A closing relaxation without gravity (`_solve.GlobalRelax`: a global
   least-squares solve per iteration, which removes such garment-wide distortion in tens of iterations where the
   Jacobi `relax` needs thousands) pulls them shut, the strokes only softly held (`stroke_hold`). Where edges
   are still over twice their length after it (growth took the cloth round the wrong side of a limb), that
   cloth is grown again from the closed cloth around it and closed again (`_mend`, `tear_strain`).
4. **Settle**: relaxation with gravity and collision, the stroke pins released (or, `settle="global"`, global
   steps with gravity, the body contacts inside the solve and static friction: `_solve.gravity_settle`).
   Optionally a band of the garment (e.g. where a kimono's obi goes) is held: its vertices over the torso are
   pinned where they are after step 3 (`_band_held`), for the settle only (the finish has no gravity).
5. **Finish**: Gauss-Seidel sweeps projecting each edge to its rest length, Chebyshev-accelerated, take back the
   stretch the settle's gravity left in cloth resting on the body and the local strain (`length_sweeps`,
   `length_chebyshev_rho`, `kitsuke.cloth.restore_lengths`; optionally after a few global relaxation steps
   without gravity, `finish_iterations`, 0 by default). The sweeps also pull each pattern stroke back within
   `stroke_reach_m` of its body stroke where the settle let it hang farther (one-sided tethers,
   `kitsuke.cloth.Tethers`), so the strokes are met and the rest drapes freely.
6. **Untangle** (`kitsuke.cloth.untangle`, also run at the end of step 3, before a hold band is pinned):
   triangles still folded over their neighbours are opened by relaxing only a few rings of cloth around them,
   the rest of the garment held still (`untangle_rounds`); the stroke tethers still apply.
7. **Polish** (`kitsuke.cloth.polish_refined`, through `_polish_step`): an L-BFGS minimisation of one energy over
   the garment (edge springs with a barrier past 2 % strain, quadratic bending, contact planes, the stroke
   tethers, the layer order) lets compressed cloth buckle into wrinkles and spreads stretch; strain-limit sweeps
   then pull the few edges it left over 4.5 % back to it; where triangles are left folded, the cloth around them
   is refined (adaptive sqrt(3), up to `polish_refine_levels`) and polished again, so the crease becomes a
   wrinkle of finer triangles; the untangle opens what is still folded. The result is kept only where it is
   better: lower max strain, and mean strain, stroke residual, folds and layer order no worse than before or
   than the targets (1 %, 10 mm, none, the layer gap). While the max strain is over 5 %, a second pass. A refined
   garment has more faces than its pattern mesh (`DressedGarment.faces`).

Layered cloth (a pattern's `meta["layers"]`: the kimono's left front over its right, SPEC §5.4) keeps its layer
order in every collision update of every step (`kitsuke.cloth.keep_layers`), so the fronts never grow or settle
through each other.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from ..body.legs import leg_gap
from ..cloth import (
    BodyCollider,
    ClothModel,
    ClothParams,
    ClothState,
    RefinedPolish,
    Tethers,
    relax,
    restore_lengths,
    untangle,
)
from ..errors import ComputationError, InputError
from ..geometry import TriMesh
from ..metrics import QualityReport, quality_report, strain
from ..pattern import Pattern, PatternMesh, face_layers, mesh_pattern
from ._bridge import bridged, spans_legs
from ._grow import grow
from ._mend import MendStats, mend_tears
from ._place import StrokeTrack, place_strokes
from ._polish_step import PolishSettings, polish_step
from ._refined import pieces_contiguous, remap_track, reorder_state
from ._solve import GlobalRelax, gravity_settle
from ._weld import repair_corners, weld
from .outcome import on_body_failures, target_misses
from .strokes import Strokes, resolve_strokes


@dataclass(frozen=True)
class WrapParams:
    """Options of `wrap`; each with its unit and reason.

    edge_length_cm : target edge length when `wrap` meshes a Pattern itself, cm.
    lift_m : the transferred stroke triangles are placed this far off the body, metres (just outside the cloth's
        contact offset, so collision does not fight the placement).
    rings_per_relax : growth rings between relaxations (more is faster, fewer keeps growth closer to the body).
    hang : how strongly cloth growing off the body turns down as it grows (`_grow.unfold`); 0 grows straight on (the
        paper's growth). Without it a kimono's sleeve, grown from its crease along the top of the arm, wraps its lower
        half round the forearm in bunches, and no settle lets it fall (it touches the arm, and friction holds it). With
        2 (`kimono.KIMONO_HANG`) it hangs as a bag below the arm: the kimono's mean / max strain 0.68 -> 0.51 % / 71 ->
        60 % at 1.5 cm edges (0.52 % / 65 % with length_collide_every 4); its max 192 -> 39 % at 2 cm and 135 -> 66 % at
        2.5 cm, with nothing torn to mend. Not the default: on fitted garments it gains nothing and can cost (shirt 0.86
        -> 0.84 % mean, hoody 0.87 -> 0.87 %; the T-shirt, whose loose front hangs off the belly, 0.40 -> 0.55 % / 12 ->
        24 % with a crease down its front; the shirt at 2.5 cm edges 3 -> 7.9 mm deepest inside).
    skirt_hang : the hang of a garment that goes round both legs (where `bridge_legs` fills the gap) when `hang`
        is 0: a skirt's flare grown straight on sticks out as a flat disc (a GarmentCode dress: its skirt torn at
        7x the length after the mend; with 2, 46 % max strain).
    hang_clearance_m : metres; cloth counts as off the body (turns down as it grows) where both vertices of the
        edge it grows from are at least this far from the body.
    grow_iterations : relaxation iterations (no gravity) after each group of rings.
    close_iterations : most iterations of the closing relaxation after growth (`_solve.GlobalRelax`: a global
        least-squares solve per iteration, no gravity); it stops early once the largest vertex move falls below
        `close_tolerance_m`. Its first ~10 steps pull the seams shut (the largest move falls from 5 cm to 3 mm on
        the shirt); later ones only creep (1 % less strain per step), which the edge-length restoration after the
        settle does faster: 15 steps and 1200 sweeps beat 40 steps and 300 sweeps on all four shipped cases.
    close_tolerance_m : metres, see close_iterations.
    close_cg_iterations : most conjugate-gradient iterations of each close step's contact solve (an inexact
        solve is enough: each step starts from the last). Mean / max strain of the whole wrap, 40 -> 10: shirt
        0.84 -> 0.86 % / 30 -> 30 %, hoody 0.82 -> 0.87 % / 24 -> 27 %, T-shirt 0.41 -> 0.40 % / 13 -> 12 %,
        kimono 0.68 -> 0.68 % / 64 -> 71 %; the shirt's close 0.45 -> 0.20 s. (20 left one shirt vertex 3.4 mm
        inside the body: the result is chaotic in it.)
    stroke_hold : weight (relative to one triangle edge) pulling the stroke vertices towards their transferred
        positions during the close; 0 lets the garment find its own rest around the strokes (measured on the
        shirt: any hold >= 0.01 raises the mean strain, the strokes ask for more than the pattern can give).
    contact_weight : weight (relative to one triangle edge) of the body contacts inside the closing solve: each
        vertex touching the body is held on the plane of its contact (normal direction only, so cloth slides;
        released where the solve pulls it off). 0 applies collision only after each solve, which fights the
        solve where it pulls cloth into the body (measured on the kimono: strain 2.5 % mean / 439 % max at 0,
        1.7 % / 84 % at 20).
    settle : "jacobi" (default): `settle_iterations` of the paper's relaxation (`kitsuke.cloth.relax`) with
        gravity, friction and collision; "global": `settle_iterations` (30 is enough) global steps
        (`_solve.gravity_settle`) with gravity `settle_gravity_m` per step and static friction `stick_weight`.
        The global settle does not stretch hanging cloth (mean strain, jacobi -> global, before the finish and
        the length restoration: shirt 2.6 -> 1.8 %; after them both end at 0.8 %), costs ~0.1-0.2 s more,
        and one of the drag scenarios of tests/dressing/test_drag.py on the kimono settled that way fails (the
        lift, on the 1.5 cm kimono; on the 3 cm one before: a folded triangle the drag's untangle did not open);
        so it is not the default.
    settle_iterations : iterations (jacobi) or steps (global) of the settle.
    settle_gravity_m : global settle: metres a free vertex falls per step.
    stick_weight : global settle: static friction (relative to one triangle edge); cloth touching the body when
        the settle starts is held along the body, so gravity does not slide the garment down the frictionless
        contact planes.
    finish_iterations : iterations of the global relaxation (with contacts, without gravity, friction or stroke
        holds, the settle's pins kept) after the settle. The Jacobi settle lets gravity stretch cloth that rests
        on the body (shirt: contact edges 2.1 % -> 4.1 % stretch), far more than real fabric stretches under its
        own weight; these steps take that back and keep the drape (shirt mean strain 2.13 -> 1.43 %, hoody 2.08
        -> 1.41 %). Off by default since the length sweeps take it back as well (measured with the sweeps
        over-relaxed): mean / max strain of the whole wrap at 10 -> 0 steps: shirt 0.75 -> 0.84 % / 28 -> 30 %,
        hoody 0.84 -> 0.82 % / 29 -> 24 %, T-shirt 0.39 -> 0.41 % / 18 -> 13 %, kimono 0.64 -> 0.68 % / 63 ->
        64 %; the shirt's wrap ~0.25 s faster (bench_wrap median 1.81-1.86 -> 1.58-1.63 s).
    length_sweeps : Gauss-Seidel sweeps of `kitsuke.cloth.restore_lengths` after the settle (with collision, the
        settle's pins kept, a hold band let go): the least-squares steps take out strain spread over the garment
        but slowly; edge projection takes out the local rest. Mean strain without -> with (15 close steps, 1200
        sweeps): shirt 1.43 -> 0.81 %, hoody 1.51 -> 0.94 %, T-shirt 1.08 -> 0.46 %, kimono 1.79 -> 0.89 %.
    length_chebyshev_rho : the length sweeps' Chebyshev acceleration (`restore_lengths`' chebyshev_rho), or
        None. Measured 2026-11-25 on the shipped cases, mean / max strain, 1200 sweeps over-relaxed at 1.5 (the
        default before) -> 400 sweeps accelerated at 0.99: shirt 0.89 -> 0.82 % / 31 -> 30 %, hoody 0.84 -> 0.83 %
        / 31 -> 25 %, T-shirt 0.40 -> 0.38 % / 12 -> 12 %, kimono 0.55 -> 0.52 % / 51 -> 41 %, in 40 % of the
        time (the shirt's finish 455 -> 192 ms). rho 0.995 overshoots (T-shirt max 23 %); 300 sweeps at 0.99
        leave more (kimono max 63 %).
    length_over_relaxation : omega of the length sweeps (`restore_lengths`' over_relaxation; 1: plain
        Gauss-Seidel). Before the acceleration, mean / max strain at 1200 sweeps, 1 -> 1.5: shirt 0.87 -> 0.75 %
        / 30 -> 28 %, T-shirt 0.46 -> 0.39 % / 26 -> 18 %. With it, leave it at 1: both at once overshoot.
    length_collide_every : a collision update after this many length sweeps. 4 rather than restore_lengths' 3:
        `bench_wrap.py --repeat 7` on the shirt, alternately, 1.28 / 1.25 s median against 1.39 / 1.58 s (a noisy
        hour), the deepest vertex 0.9 mm out of the body instead of 1.5 mm; mean / max strain shirt 0.89 % / 31 %,
        hoody 0.84 % / 31 %, T-shirt 0.40 % / 12 %, kimono 0.52 % / 65 %, nothing inside or folded. 6 left a shirt
        vertex 2.4 mm inside the body.
    stroke_reach_m : metres, or None. The length restoration and the last untangle keep every pattern stroke
        within this distance of its body stroke (`kitsuke.cloth.Tethers`: a one-sided pull on the stroke's 32
        samples, only where they have settled farther). The settled garment rests where gravity and its ease put
        it, 15-22 mm from the shipped strokes (a loose shirt's front hangs off the belly, a hood behind the
        head); a user who drew a line meant it there. Measured with 8 mm on the shipped cases (residual and mean
        strain without -> with, the last untangle at bend 0.3): shirt 20.6 -> 8.6 mm, 0.81 -> 0.94 %; hoody
        22.2 -> 8.4 mm, 0.94 -> 0.98 %; T-shirt 14.9 -> 8.2 mm, 0.46 -> 0.55 %; kimono 19.6 -> 8.8 mm, 0.89 ->
        0.95 %. None: no pull.
    tether_slack_m : metres. A stroke whose cloth the settle left farther than this from its body stroke is not
        tethered (`stroke_reach_m`): the pattern cannot lie there without stretching, and pulling it back tears the
        cloth; its residual is reported (`DressedGarment.loose_strokes`). The shipped cases settle 15-22 mm away.
    tether_strain : a strain. Where the finish and polish with the stroke tethers leave an edge strained more than
        this, they run again without them, and the strokes are let go (`loose_strokes`) if that halves the max
        strain and brings it within twice MAX_STRAIN_TARGET: the strokes ask for what the pattern cannot give.
    untangle_bend : hinge stiffness of the last untangle (`kitsuke.cloth.untangle`'s bend_stiffness; the one
        after the close keeps its 0.3). The folds left after the length restoration are where the sweeps laid
        spare cloth flat; a stiff hinge opens them into strained cloth. Mean / max strain at 0.3 -> 0.1: shirt
        0.94 -> 0.87 % / 31 -> 31 %, hoody 0.98 -> 0.87 % / 31 -> 29 %, T-shirt 0.55 -> 0.46 % / 30 -> 26 %,
        kimono 0.95 -> 0.64 % / 82 -> 65 %; at 0.02 two kimono triangles stay folded.
    tear_strain : fraction, or None. After the close, cloth round edges stretched more than this (1.0: twice
        their rest length) is grown again from the closed cloth around it and closed again (`_mend.mend_tears`):
        where growth wrapped it round the wrong side of a limb, the limb goes through it and the close cannot pull
        it back. Max strain of the finished wrap without -> with: GarmentCode's shirt at 1 cm 774 -> 40 %, at
        2 cm 433 -> 37 %; the kimono's sleeves at 2-2.5 cm stay torn (177 -> 301 %, 276 -> 130 %: regrown, they
        catch on the forearm again). The shipped 1.5 cm cases never reach it (worst after the close: 83 %), so
        they are unchanged. None: no mending.
    mend_rounds : most mending rounds (0: none).
    untangle_rounds : most rounds of `kitsuke.cloth.untangle` after the close and at the end (0: none). Measured
        on GarmentCode's hoody on mean_all: 7 folded triangles at the neckline after the finish, 0 after one
        round, the rest of the garment untouched; the kimono: 16 -> 0 (one of them inside the obi band, which
        only the untangle after the close can reach).
    polish_rounds : rounds of `kitsuke.cloth.polish` at the end (0: none), each of up to `polish_iterations` L-BFGS
        iterations; its result is kept only if better (see the module docstring, step 7, and `_polish_step`).
        Measured 2026-11-25 (with everything below): mean / max strain GarmentCode's shirt 0.84 / 28.7 -> 0.77 /
        4.6 %, hoody 0.83 / 25.3 -> 0.37 / 4.5 %, the FreeSewing T-shirt 0.38 / 11.6 -> 0.27 / 4.5 %; the kimono's
        is not kept (its fronts pushed through each other).
    polish_refine_levels : where the polish leaves triangles folded (at most `polish_refine_max_folds` of them), up
        to this many adaptive sqrt(3) levels of the cloth within `polish_refine_rings` rings of the folds, each
        polished again with up to `polish_refine_iterations` L-BFGS iterations per round (`polish_refined`): the
        crease becomes a wrinkle of finer triangles instead of being pressed flat by the untangle. The garment then
        has more faces than its pattern mesh (the OBJ's `vt` still give every corner's pattern position). Measured
        2026-11-25 on GarmentCode's hoody (3 mm offset): 9 folded triangles after the polish, 0 after 3 levels, max
        strain 4.5 % (32 % polished and untangled); 0: no refinement.
    polish_strain_limit, polish_limit_sweeps : after each polish, up to this many Gauss-Seidel sweeps (400 between
        refinement levels) pull every edge strained more than the limit back to it, and leave the others alone
        (`restore_lengths` with a band), the stroke tethers and collision kept. The polish spreads strain but its
        barrier is soft (a stiffer one stalls L-BFGS); the limit takes the few edges it left over 5 % under without
        the equal-length sweeps' flattening of its buckles. Over 1 nm changes of the body the shirt ended at
        4.66-4.68 % with 1000 sweeps (4.58-4.86 % with 1500 and a barrier a third as stiff). 0 sweeps: none.
    polish_passes : most polish passes; a later one runs only while the max strain is over 5 %, from the better
        cloth the last one kept.
    bridge_legs : fill the gap between the legs (`kitsuke.body.legs`) for the growth, the close and the mend, so
        cloth grown over the hips drapes round both legs; None (default): when the garment has an opening below
        the crotch that goes round both legs by its placement (`_bridge.spans_legs`: a skirt's hem, not a trouser
        leg's); True / False: always / never.
    release_strokes : unpin the stroke triangles for the settle (the paper lets the garment settle freely);
        False keeps them where the strokes put them.
    hold_band_m : (low, high) heights in metres, or None: garment vertices in this band are pinned for the settle
        (a kimono's waist, held by the obi), where they are within `hold_reach_m` of the body.
    hold_reach_m : metres; the hold band holds only cloth this close to the body and, on a rigged body, over the
        torso (what a tied obi presses on; the kimono's overlapping fronts and looser folds lie centimetres out).
        See `_band_held`.
    cloth : ClothParams of the Jacobi relaxation (growth, without gravity; the default settle, with it), of the
        untangle and of the returned model (a later drag). Strain limiting is off by default: where the grown
        garment is still strained at seams, it would drag the whole garment towards its supports in one
        iteration (measured on the shirt: the shirt ends up a scarf).
    """

    edge_length_cm: float = 1.5
    lift_m: float = 0.004
    rings_per_relax: int = 1
    hang: float = 0.0
    skirt_hang: float = 2.0
    hang_clearance_m: float = 0.03
    grow_iterations: int = 2
    close_iterations: int = 15
    close_tolerance_m: float = 2e-4
    close_cg_iterations: int = 10
    stroke_hold: float = 0.01
    contact_weight: float = 20.0
    settle: str = "jacobi"
    settle_iterations: int = 60
    settle_gravity_m: float = 0.002
    stick_weight: float = 20.0
    finish_iterations: int = 0
    length_sweeps: int = 400
    length_chebyshev_rho: float | None = 0.99
    length_over_relaxation: float = 1.0
    length_collide_every: int = 4
    stroke_reach_m: float | None = 0.008
    untangle_bend: float = 0.1
    tether_slack_m: float = 0.03
    tether_strain: float = 0.15
    tear_strain: float | None = 1.0
    mend_rounds: int = 3
    untangle_rounds: int = 10
    polish_rounds: int = 8
    polish_iterations: int = 40
    polish_refine_levels: int = 5
    polish_refine_rings: int = 2
    polish_refine_iterations: int = 80
    polish_refine_max_folds: int = 60
    polish_passes: int = 2
    polish_strain_limit: float = 0.045
    polish_limit_sweeps: int = 1000
    release_strokes: bool = True
    bridge_legs: bool | None = None
    hold_band_m: tuple[float, float] | None = None
    hold_reach_m: float = 0.05
    cloth: ClothParams = field(default_factory=lambda: ClothParams(max_stretch=None))

    @classmethod
    def strokes_held(cls, **changes) -> WrapParams:
        """Parameters that make the strokes constraints rather than a starting placement: held firmly in the close
        and kept where they lie through the settle, so the garment hangs from them. Strokes are then met within
        millimetres, and where they ask for more than the pattern gives, the cloth stretches instead (measured on
        the shipped strokes against the default's tethers: residual shirt 7.6 mm vs 8.6 mm, T-shirt 6.5 vs 8.2 mm;
        mean strain shirt 1.42 vs 0.94 %, T-shirt 0.77 vs 0.55 %). `changes` as for WrapParams."""
        return cls(**{"stroke_hold": 1.0, "release_strokes": False, **changes})

    def __post_init__(self) -> None:
        for name in ("rings_per_relax", "close_cg_iterations", "length_collide_every"):
            if getattr(self, name) < 1:
                raise InputError(f"wrap parameter {name} must be >= 1")
        for name in (
            "grow_iterations",
            "close_iterations",
            "settle_iterations",
            "finish_iterations",
            "length_sweeps",
            "mend_rounds",
            "untangle_rounds",
            "polish_rounds",
            "polish_refine_levels",
            "polish_refine_rings",
            "polish_refine_max_folds",
            "polish_limit_sweeps",
            "polish_passes",
        ):
            if getattr(self, name) < 0:
                raise InputError(f"wrap parameter {name} must be >= 0")
        if not (
            self.edge_length_cm > 0
            and self.tether_slack_m > 0
            and self.lift_m >= 0
            and self.close_tolerance_m >= 0
            and self.stroke_hold >= 0
            and self.contact_weight >= 0
        ):
            raise InputError(
                "wrap parameters edge_length_cm > 0, tether_slack_m > 0, lift_m >= 0, close_tolerance_m >= 0, "
                "stroke_hold >= 0, "
                "contact_weight >= 0 required"
            )
        if self.settle not in ("jacobi", "global"):
            raise InputError(f'wrap parameter settle must be "jacobi" or "global", got {self.settle!r}')
        if not (self.settle_gravity_m >= 0 and self.stick_weight >= 0):
            raise InputError("wrap parameters settle_gravity_m >= 0 and stick_weight >= 0 required")
        if self.hold_band_m is not None and not (
            len(self.hold_band_m) == 2 and self.hold_band_m[0] < self.hold_band_m[1]
        ):
            raise InputError("hold_band_m must be (low, high) with low < high, metres")
        if (
            not (np.isfinite(self.hang) and self.hang >= 0 and np.isfinite(self.skirt_hang) and self.skirt_hang >= 0)
            or not self.hang_clearance_m >= 0
        ):
            raise InputError("wrap parameters hang, skirt_hang >= 0 (finite) and hang_clearance_m >= 0 required")
        if self.polish_iterations < 1 or self.polish_refine_iterations < 1:
            raise InputError("wrap parameters polish_iterations and polish_refine_iterations must be >= 1")
        if not 0.0 <= self.polish_strain_limit < 1.0:
            raise InputError("wrap parameter polish_strain_limit must be a strain in [0, 1)")
        if not self.untangle_bend >= 0:
            raise InputError("wrap parameter untangle_bend must be >= 0")
        if self.stroke_reach_m is not None and not self.stroke_reach_m > 0:
            raise InputError("wrap parameter stroke_reach_m must be > 0 (metres) or None")
        if not 1.0 <= self.length_over_relaxation < 2.0:
            raise InputError("wrap parameter length_over_relaxation must be in [1, 2)")
        if self.length_chebyshev_rho is not None and not 0.0 < self.length_chebyshev_rho < 1.0:
            raise InputError("wrap parameter length_chebyshev_rho must be in (0, 1) or None")
        if self.tear_strain is not None and not self.tear_strain > 0:
            raise InputError("wrap parameter tear_strain must be > 0 (a fraction: 1.0 = twice the rest length) or None")
        if not self.hold_reach_m > 0:
            raise InputError("wrap parameter hold_reach_m must be > 0 (metres)")


@dataclass
class DressedGarment:
    """A garment on a body.

    Attributes
    ----------
    name : the pattern's name.
    piece_names : (P,) piece names. piece_faces : (P, 2) int64, [start, stop) face range of each piece.
    positions : (V, 3) float64, metres, world frame (Y up); seam vertices shared between pieces.
    faces : (F, 3) int64, counter-clockwise seen from outside the garment (each piece's outer face).
    corner_uv : (F, 3, 2) float64, metres: each corner's pattern position in its piece (SPEC §3.3 `vt`).
    pattern_vertex : (Vp,) int64, the garment vertex of each vertex of the PatternMesh it came from (after
        `repair_corners`, which may add a few vertices at the end of a piece: see `pattern_mesh`).
    pattern_mesh : that PatternMesh.
    model : the ClothModel (rest shape, rest lengths); pinned : (V,) bool, vertices held at the end (hold band).
    stroke_ids : stroke ids in drawing order. stroke_residual_m : (S,) float64 metres, for each stroke the largest
        distance of its pattern stroke (on the garment) to its body stroke after the settle.
    stroke_length_ratio : (S,) body stroke length / pattern stroke length (the cloth keeps its own length).
    loose_strokes : ids of the strokes not held to their body strokes after the settle (`tether_slack_m`).
    rings : growth rings. mend : what `_mend.mend_tears` did after the close (rounds, torn edges before and
        after). polished : the polish's result was kept (`WrapParams.polish_rounds`). timings : seconds per step
        ("mesh", "resolve", "place", "grow", "close", "settle", "finish", "untangle", "polish", "wrap" = all of
        them, "report").
    report : the SPEC §6 quality report against the body.
    """

    name: str
    piece_names: list[str]
    piece_faces: np.ndarray
    positions: np.ndarray
    faces: np.ndarray
    corner_uv: np.ndarray
    pattern_vertex: np.ndarray
    pattern_mesh: PatternMesh = field(repr=False)
    model: ClothModel = field(repr=False)
    pinned: np.ndarray = field(repr=False)
    stroke_ids: list[int] = field(default_factory=list)
    stroke_residual_m: np.ndarray = field(default_factory=lambda: np.zeros(0))
    stroke_length_ratio: np.ndarray = field(default_factory=lambda: np.zeros(0))
    tracks: list[StrokeTrack] = field(default_factory=list, repr=False)
    loose_strokes: list[int] = field(default_factory=list)
    rings: int = 0
    mend: MendStats = field(default_factory=MendStats)
    polished: bool = False
    timings: dict[str, float] = field(default_factory=dict)
    report: QualityReport | None = None

    @property
    def n_vertices(self) -> int:
        return len(self.positions)

    @property
    def max_stroke_residual_m(self) -> float:
        return float(self.stroke_residual_m.max(initial=0.0))

    def to_trimesh(self) -> TriMesh:
        """The garment as a TriMesh (no uv: the pattern uv is per corner, see corner_uv)."""
        return TriMesh(self.positions, self.faces, name=self.name)

    def summary(self) -> dict:
        """JSON-ready counts, timings, stroke residuals and the quality report."""
        return {
            "name": self.name,
            "vertices": self.n_vertices,
            "faces": len(self.faces),
            "rings": self.rings,
            "held_vertices": int(self.pinned.sum()),
            "mend": dataclasses.asdict(self.mend),
            "polished": self.polished,
            "loose_strokes": list(self.loose_strokes),
            "timings_s": {k: round(v, 4) for k, v in self.timings.items()},
            "strokes": [
                {
                    "id": i,
                    "residual_mm": round(float(r) * 1e3, 2),
                    "length_ratio": round(float(q), 4),
                    "reversed": bool(tr.reversed) if tr is not None else False,
                }
                for i, r, q, tr in zip(
                    self.stroke_ids,
                    self.stroke_residual_m,
                    self.stroke_length_ratio,
                    self.tracks or [None] * len(self.stroke_ids),
                    strict=True,
                )
            ],
            "quality": None if self.report is None else self.report.to_dict(),
            "targets_missed": None if self.report is None else target_misses(self),
        }


def offset_as_dressed(garment, cloth: ClothParams) -> ClothParams:
    """`cloth` with the contact offset a DressedGarment was dressed with, or a GarmentFile's OBJ says, where `cloth`
    keeps ClothParams' default (a kimono, over its under-kimonos, lies 3 mm off: a drag or re-wrap at 1 mm pulls it
    in and strains it, and the body shows through between its vertices; the rough drags of
    tests/dressing/test_drag.py: 0.49 -> 0.94-1.04 % mean strain). A file that does not say: `cloth` as it is."""
    if isinstance(garment, DressedGarment):
        offset = garment.model.params.contact_offset_m
    else:
        offset = getattr(garment, "contact_offset_m", None)  # a GarmentFile (export imports this module)
    if offset is not None and cloth.contact_offset_m == ClothParams().contact_offset_m:
        return dataclasses.replace(cloth, contact_offset_m=offset)
    return cloth


#: Bones whose skin a hold band presses on (an obi ties round the torso, not round an arm hanging beside it).
TORSO = ("pelvis", "spine", "chest")


def _band_held(body, mesh: TriMesh, state: ClothState, band: tuple[float, float], reach_m: float) -> np.ndarray:
    """(V,) bool: garment vertices that a band tied round the body at heights `band` (metres) holds: in the band,
    within `reach_m` of the body and, for a rigged body, over its torso (the nearest body point's skin mostly
    moved by TORSO). Without the last two tests the kimono's obi band also held the sleeves where they hang over
    the forearms at waist height (measured at 3 cm: a sleeve vertex next to a held one thrown 34 cm)."""
    y = state.positions[:, 1]
    c = state.contacts
    held = (y >= band[0]) & (y <= band[1]) & c.touching(reach_m)
    rig = getattr(body, "rig", None)
    if rig is not None and len(rig.weights) == len(mesh.vertices):
        torso = rig.weight_of(TORSO)[mesh.faces[np.maximum(c.face, 0)]].mean(axis=1) >= 0.5
        held &= torso
    return held


#: Issue 3's max edge strain target: the polish runs another pass while the garment is over it.
MAX_STRAIN_TARGET = 0.05


def wrap(
    body,
    garment: Pattern | PatternMesh,
    strokes: Strokes,
    *,
    pattern: Pattern | None = None,
    params: WrapParams | None = None,
    collider: BodyCollider | None = None,
    report: bool = True,
    check: bool = True,
    progress: Callable[[str], None] | None = None,
) -> DressedGarment:
    """Dress `body` with `garment` placed by `strokes` (SPEC §4.2); see the module docstring for the steps.

    body : a `kitsuke.body.Body` (or a closed TriMesh).
    garment : a Pattern (meshed here at `params.edge_length_cm`) or an already meshed PatternMesh.
    strokes : stroke pairs; body strokes not yet resolved are put on the body here (`resolve_strokes`), which
        needs the Pattern (`garment` itself, or `pattern=` with a PatternMesh).
    collider : a prepared BodyCollider for `body` (built if None); its Surface (one AABB tree, ~50 ms to build on
        mean_all) also places and resolves the strokes, so pass the same collider to repeated wraps.
    report : compute the quality report (a winding-number test; not part of the wrap's time).
    check : raise ComputationError (with the garment as its `result`) when the result is not a garment on the
        body (`kitsuke.dressing.on_body_failures`: non-finite, a piece off the body, torn cloth, a stroke far from
        where it was drawn); a stage that goes non-finite raises it whatever `check` says.
    progress : called with each stage's name as it starts ("meshing", "placing", ...), for a progress display.
    Raises InputError for strokes naming a missing piece or crossing no triangle, a body with holes, and a
    garment that the strokes cannot reach (a piece joined by no seam to any piece with a stroke).
    """
    p = params or WrapParams()
    if not isinstance(p, WrapParams):
        raise InputError("params must be a WrapParams")
    if not isinstance(strokes, Strokes):
        raise InputError("strokes must be a kitsuke.dressing.Strokes")
    if not len(strokes):
        raise InputError("no strokes: the wrap needs at least one stroke pair", strokes.source or None)
    if strokes.target != "body":
        raise InputError("wrap dresses a body: these strokes target a garment (use a re-wrap)", strokes.source or None)
    timings: dict[str, float] = {}
    say = progress or (lambda _stage: None)
    t0 = time.perf_counter()
    say("meshing")
    if isinstance(garment, Pattern):
        pattern = garment
        pm = mesh_pattern(garment, edge_length=p.edge_length_cm)
    elif isinstance(garment, PatternMesh):
        pm = garment
    else:
        raise InputError("garment must be a Pattern or a PatternMesh")
    # Corners where two seams of one piece meet would sew into coinciding triangles: split them (usually a no-op).
    pm = repair_corners(pm, None if pattern is None else pattern.seams)
    mesh = body if isinstance(body, TriMesh) else body.mesh
    t1 = time.perf_counter()
    timings["mesh"] = t1 - t0
    say("resolving the strokes")
    if collider is None:
        collider = BodyCollider.from_mesh(mesh) if isinstance(body, TriMesh) else BodyCollider.from_body(body)
    surface = collider.surface_for(mesh)
    if not strokes.resolved:
        if pattern is None:
            raise InputError("strokes are not on the body yet: pass pattern= to resolve them", strokes.source or None)
        strokes = resolve_strokes(strokes, pattern, surface, pattern_mesh=pm)
    else:
        for pair in strokes.pairs:
            if pair.pattern.piece not in pm.piece_names:
                raise InputError(
                    f"stroke {pair.id}: pattern piece {pair.pattern.piece!r} is not in pattern {pm.name!r}",
                    strokes.source or None,
                )
    t2 = time.perf_counter()
    timings["resolve"] = t2 - t1
    say("placing the pieces")

    welded = weld(pm)
    shaping = collider  # growth, close and mend run against the body with its leg gap filled, for a skirt
    hang = p.hang
    gap = leg_gap(mesh) if p.bridge_legs is not False else None
    if gap is not None and (p.bridge_legs or spans_legs(pm, welded, gap.crotch_y)):
        shaping = bridged(collider, gap)
        hang = hang or p.skirt_hang
    placements = None if pattern is None else {pc.name: pc.placement for pc in pattern.pieces if pc.placement}
    placement = place_strokes(pm, welded, strokes, surface, collider, lift_m=p.lift_m, placements=placements)
    grow_params = dataclasses.replace(p.cloth, gravity_step_m=0.0)
    layer = face_layers(pm.layers, pm.piece_names, welded.piece_faces, welded.rest_corners * 100.0)
    model = ClothModel.from_corners(
        welded.faces, welded.rest_corners, n_vertices=welded.n_vertices, params=grow_params, face_layer=layer
    )
    state = ClothState.new(model, placement.positions, pinned=placement.placed.copy(), face_active=placement.seed_faces)
    seed_pins = placement.placed.copy()
    t3 = time.perf_counter()
    timings["place"] = t3 - t2
    say("growing the cloth")

    def grow_from(placed: np.ndarray) -> int:
        """Grow the inactive triangles from the placed vertices; also the mend's regrowth."""
        return grow(
            model,
            state,
            placed,
            lambda _ring: relax(model, state, shaping, iterations=p.grow_iterations),
            rings_per_relax=p.rings_per_relax,
            hang=hang,
            hang_clearance_m=p.hang_clearance_m,
        )

    # The seed faces' vertices are placed; faces whose three vertices are placed (next to a seed) join at once.
    rings = grow_from(placement.placed.copy())
    if not state.face_active.all():
        missing = np.flatnonzero(~state.face_active)
        piece_of = np.searchsorted(welded.piece_faces[:, 1], missing, side="right")
        names = sorted({pm.piece_names[i] for i in np.unique(piece_of)})
        raise InputError(
            f"no stroke reaches piece(s) {', '.join(names)}: draw a stroke on them or sew them to a piece that has one",
            strokes.source or None,
        )
    _finite(state, "grow")
    t4 = time.perf_counter()
    timings["grow"] = t4 - t3
    say("closing the seams")

    # Close: the global relaxation (see _solve), stroke pins released so that collision reaches the stroke
    # triangles too; they are only held softly towards where the strokes put them (`stroke_hold`).
    state.pinned = np.zeros(model.n_vertices, dtype=bool)
    mended = MendStats()
    if p.close_iterations:
        targets = state.positions.copy()

        # A fresh solver for every close: after the mend regrows cloth, contacts the last close had released must
        # hold again (measured on the kimono at 2.5 cm: one solver kept edges 238 % long after the mend, fresh
        # ones 116 %).
        def close() -> None:
            solver = GlobalRelax(
                model,
                state.pinned,
                held=seed_pins,
                targets=targets,
                hold_weight=p.stroke_hold,
                contact_weight=p.contact_weight,
                cg_iterations=p.close_cg_iterations,
            )
            for _ in range(p.close_iterations):
                if solver.step(state, shaping) < p.close_tolerance_m:
                    break

        close()
        if p.tear_strain is not None and p.mend_rounds:
            mended = mend_tears(
                model,
                state,
                placement.seed_faces,
                grow_from,
                close,
                tear_strain=p.tear_strain,
                rounds=p.mend_rounds,
            )
    if p.untangle_rounds:  # before the hold band is pinned: a fold inside the band could not open later
        untangle(model, state, shaping, rounds=p.untangle_rounds)
    _finite(state, "close")
    t5 = time.perf_counter()
    timings["close"] = t5 - t4
    say("settling")

    settle = model.with_params(p.cloth)
    pins = np.zeros(model.n_vertices, dtype=bool) if p.release_strokes else seed_pins.copy()
    band = np.zeros(model.n_vertices, dtype=bool)
    if p.hold_band_m is not None:
        band = _band_held(body, mesh, state, p.hold_band_m, p.hold_reach_m) & ~pins
        pins |= band
    state.pinned = pins
    if p.settle_iterations and p.settle == "jacobi":
        relax(settle, state, shaping, iterations=p.settle_iterations)
    elif p.settle_iterations:
        gravity_settle(
            model,
            state,
            collider,
            pins,
            iterations=p.settle_iterations,
            gravity_m=p.settle_gravity_m,
            stick_weight=p.stick_weight,
            contact_weight=p.contact_weight,
        )
    _finite(state, "settle")
    t_settled = time.perf_counter()
    timings["settle"] = t_settled - t5
    say("restoring lengths and polishing")
    # The band holds the cloth up against gravity; the finish and the length restoration have none, so they let
    # it go: pinned where the close left it, the kimono's back under the obi kept 5-20 % strain (mean strain
    # 1.22 % held, 0.95 % let go).
    unheld = pins & ~band
    tethers = None
    # A stroke whose cloth settled far from it is not pulled back: where the pattern cannot lie along the stroke
    # without stretching, the pull tears it (a crop top on suggested strokes that slid 8 cm in the close: 44 ->
    # 249 % max strain with its tethers, 19 % without). Its residual is reported instead.
    settled = np.array([tr.residual_m(state.positions, model.faces) for tr in placement.tracks])
    loose = settled > p.tether_slack_m
    if p.stroke_reach_m is not None and not loose.all():
        tethers = Tethers.from_polylines(
            [(tr.faces, tr.bary, tr.body_path) for tr, far in zip(placement.tracks, loose, strict=True) if not far],
            model.faces,
            p.stroke_reach_m,
        )

    def finish_and_polish(state: ClothState, tethers: Tethers | None, loose: np.ndarray) -> tuple:
        """Steps 5-7 from the settled `state`: (state, out_model, piece_faces, corner_uv, tracks, polished)."""
        t_settled = time.perf_counter()
        if p.finish_iterations:
            finish = GlobalRelax(model, unheld, contact_weight=p.contact_weight)
            for _ in range(p.finish_iterations):
                if finish.step(state, collider) < p.close_tolerance_m:
                    break
        if p.length_sweeps:
            state.pinned = unheld
            # The projection moves vertices along edges, across the body's surfaces where arm and torso meet: search
            # every vertex's nearest point afresh first (`Contacts.forget`; measured on the shirt without it: one
            # vertex left 2.4 mm inside the torso, tracked to the arm).
            state.contacts.forget()
            restore_lengths(
                settle,
                state,
                collider,
                sweeps=p.length_sweeps,
                tethers=tethers,
                over_relaxation=p.length_over_relaxation,
                chebyshev_rho=p.length_chebyshev_rho,
                collide_every=p.length_collide_every,
            )
            state.pinned = pins
        _finite(state, "length restoration")
        t_finished = time.perf_counter()
        timings["finish"] = t_finished - t_settled
        if p.untangle_rounds:
            # Without gravity, like the length restoration: the band is let go here too (a fold the sweeps left in it,
            # where the kimono's layers lie pressed on each other, could not open otherwise).
            state.pinned = unheld
            untangle(settle, state, collider, rounds=p.untangle_rounds, bend_stiffness=p.untangle_bend, tethers=tethers)
            state.pinned = pins
        t_untangled = time.perf_counter()
        timings["untangle"] = t_untangled - t_finished

        polished = False
        out_model, piece_faces, corner_uv, tracks = settle, welded.piece_faces, welded.rest_corners, placement.tracks

        # The stroke samples of the garment as it is (out_model, tracks: refined by a kept polish), or of the refined
        # polish rp made of it (its samples moved onto its new faces: between their old corners they lie off the
        # refined surface; the kimono's sleeve crease 12.0 mm from its stroke that way where it measured 8.7 mm).
        refined_tracks: dict[int, tuple] = {}  # id(rp) -> (its PieceOrdered, the tracks on it): made once, used twice

        def on_refined(rp: RefinedPolish) -> tuple:
            if id(rp) not in refined_tracks:
                ordered = pieces_contiguous(rp, piece_faces)
                refined_tracks.clear()
                refined_tracks[id(rp)] = (ordered, [remap_track(tr, corner_uv, piece_faces, ordered) for tr in tracks])
            return refined_tracks[id(rp)]

        def residual_of(positions: np.ndarray, rp: RefinedPolish | None = None) -> np.ndarray:
            if rp is None or not rp.levels:
                return np.array([tr.residual_m(positions, out_model.faces) for tr in tracks])
            ordered, moved = on_refined(rp)
            return np.array([tr.residual_m(positions, ordered.model.faces) for tr in moved])

        settings = PolishSettings(
            rounds=p.polish_rounds,
            iterations=p.polish_iterations,
            levels=p.polish_refine_levels,
            rings=p.polish_refine_rings,
            refine_iterations=p.polish_refine_iterations,
            max_folds=p.polish_refine_max_folds,
            strain_limit=p.polish_strain_limit,
            limit_sweeps=p.polish_limit_sweeps,
            untangle_rounds=p.untangle_rounds,
            untangle_bend=p.untangle_bend,
        )
        passes = 0
        level = pending = None
        while p.polish_rounds and passes < p.polish_passes:
            # A later pass only while the max strain is still over the target: it starts from the better cloth and
            # takes another path to the buckles (chaotic: GarmentCode's shirt at 1.45-1.6 cm edges ends at 4.6-28 %
            # after one pass).
            if passes and strain(state.positions, out_model.edges, out_model.rest_lengths).max <= MAX_STRAIN_TARGET:
                break
            passes += 1
            extra = np.zeros(out_model.n_vertices - len(pins), dtype=bool)
            state.pinned = np.concatenate([unheld, extra])
            kept, rp = polish_step(
                out_model,
                state,
                collider,
                settings,
                tethers=tethers,
                corner_data={"uv": corner_uv},
                residual_of=residual_of,
                level=level,
                pending=pending,
            )
            state.pinned = np.concatenate([pins, extra])
            if not kept:
                break
            polished = True
            state = rp.state
            state.pinned = np.concatenate([pins, np.zeros(rp.model.n_vertices - len(pins), dtype=bool)])
            if rp.levels:
                ordered, tracks = on_refined(rp)
                state = reorder_state(state, ordered)
                level, pending = ordered.level, ordered.pending
                out_model, piece_faces, corner_uv = ordered.model, ordered.piece_faces, ordered.corner_uv
                if tethers is not None:  # a later pass holds the strokes on the refined faces
                    tethers = Tethers.from_polylines(
                        [(tr.faces, tr.bary, tr.body_path) for tr, far in zip(tracks, loose, strict=True) if not far],
                        out_model.faces,
                        p.stroke_reach_m,
                    )
        _finite(state, "polish")
        timings["polish"] = time.perf_counter() - t_untangled
        return state, out_model, piece_faces, corner_uv, tracks, polished

    settled_state = state.copy() if tethers is not None else None
    state, out_model, piece_faces, corner_uv, tracks, polished = finish_and_polish(state, tethers, loose)
    held = strain(state.positions, out_model.edges, out_model.rest_lengths).max
    if settled_state is not None and held > p.tether_strain:
        # Strokes the cloth cannot lie along without stretching (a shirt's strokes drawn 2 cm below where its
        # shoulders can go: 46 % max strain held there, 4.6 % let go): the same steps without their tethers, kept
        # when they halve the max strain and end within twice its target; the strokes are then reported loose.
        spent = {k: timings[k] for k in ("finish", "untangle", "polish")}
        free = finish_and_polish(settled_state, None, np.ones_like(loose))
        loose_max = strain(free[0].positions, free[1].edges, free[1].rest_lengths).max
        if loose_max < 0.5 * held and loose_max <= 2 * MAX_STRAIN_TARGET:
            (state, out_model, piece_faces, corner_uv, tracks, polished), loose = free, np.ones_like(loose)
        for k, v in spent.items():
            timings[k] += v
    t6 = time.perf_counter()
    timings["wrap"] = t6 - t0

    residual = np.array([tr.residual_m(state.positions, out_model.faces) for tr in tracks])
    ratio = np.array([tr.body_length_m / tr.pattern_length_m for tr in placement.tracks])
    result = DressedGarment(
        name=pm.name,
        piece_names=list(pm.piece_names),
        piece_faces=piece_faces,
        positions=state.positions,
        faces=out_model.faces,
        corner_uv=corner_uv,
        pattern_vertex=welded.vertex_of,
        pattern_mesh=pm,
        model=out_model,
        pinned=state.pinned,
        stroke_ids=[tr.id for tr in placement.tracks],
        stroke_residual_m=residual,
        stroke_length_ratio=ratio,
        tracks=tracks,
        loose_strokes=[tr.id for tr, far in zip(placement.tracks, loose, strict=True) if far],
        rings=rings,
        polished=polished,
        mend=mended,
        timings=timings,
    )
    if report:
        result.report = quality_report(
            state.positions,
            out_model.faces,
            mesh,
            rest_lengths=out_model.rest_lengths,
            rest_areas=out_model.rest_areas,
            pieces=(result.piece_names, result.piece_faces),
        )
        timings["report"] = time.perf_counter() - t6
    if check:
        bad = on_body_failures(result, body, surface=surface)
        if bad:
            more = f" (and {len(bad) - 1} more)" if len(bad) > 1 else ""
            raise ComputationError("wrap", f"not a garment on the body: {bad[0]}{more}", result=result)
    return result


def _finite(state: ClothState, stage: str) -> None:
    """Raise ComputationError naming the wrap stage after which a position is no longer finite."""
    if not np.isfinite(state.positions).all():
        n = int((~np.isfinite(state.positions).all(axis=1)).sum())
        raise ComputationError(f"wrap: {stage}", f"{n} cloth positions became non-finite")
