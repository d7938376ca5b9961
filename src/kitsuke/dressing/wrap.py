"""The wrap (SPEC §4.2): put a sewing pattern on a body from corresponding strokes.

    from kitsuke.dressing import wrap, WrapParams
    garment = wrap(body, pattern, strokes)                    # DressedGarment
    garment.report.ok, garment.stroke_residual_m, garment.timings

Steps (the paper's, with the interpretations of SPEC §4.2):

1. **Transfer** (`_place`): the pattern triangles each pattern stroke crosses are laid on the body along its body
   stroke, at the cloth's own length with the middles together (the body stroke continued straight past its ends
   where it is shorter; offsets across the stroke laid out on the surface; `grow.lift_m` off it), the body stroke
   taken the way round the placement or the pattern's up says.
2. **Growth** (`_grow`): the rest of the garment grows ring by ring from the placed triangles, each new triangle
   unfolded from its placed neighbour (from the cloth, not the body), with relaxation and collision between rings.
   The stroke triangles stay pinned while the garment grows. Pieces named in `grow.laid` are not grown but laid
   where the pattern's placement puts them (`_laid`; "*": every placed piece); a wrap whose result has a piece
   without strokes on the wrong side of the body (`outcome.wrong_side_pieces`) lays those pieces and dresses once
   more, and one that fails otherwise (torn round a limb, off the body), or fails again, dresses once more with
   every placed piece laid (`grow.relay`; at most two such tries after a failed one).
3. **Seams**: the garment mesh shares the vertices of every seam from the start (`_weld`; corners where two seams
   of one piece meet are repaired first, `repair_corners`), so where two grown regions meet at a seam the
   triangles between them are stretched. A closing relaxation without gravity (`_solve.GlobalRelax`: a global
   least-squares solve per iteration, which removes such garment-wide distortion in tens of iterations where the
   Jacobi `relax` needs thousands) pulls them shut, the strokes only softly held (`close.stroke_hold`). Where edges
   are still over twice their length after it (growth took the cloth round the wrong side of a limb), that
   cloth is grown again from the closed cloth around it and closed again (`_mend`, `close.tear_strain`).
   A wrap that still fails after its relay (step 2) is dressed once more with its seams *sewn* instead
   (`close.sew_on_failure`, `kitsuke.cloth.sew`): the dynamic solver without gravity pulls each stretched edge
   back a centimetre a frame, so no cloth moves far enough at once to pass through a limb.
4. **Settle**: relaxation with gravity and collision, the stroke pins released (or, `settle.method="global"`, global
   steps with gravity, the body contacts inside the solve and static friction: `_solve.gravity_settle`).
   Optionally a band of the garment (e.g. where a kimono's obi goes) is held: its vertices over the torso are
   pinned where they are after step 3 (`_band_held`), for the settle only (the finish has no gravity).
4b. **Drape** (`_stages.drape_stage`): where much of the garment hangs off the body (a flared skirt, a gown),
   the hanging cloth falls under gravity for a simulated second in the dynamic solver (`kitsuke.cloth.step`,
   XPBD with the body's collision and a 2 % strain limit), the cloth resting on the body held where the settle
   left it. A relaxation from a flat start cannot let a flare fall: its hem would have to gather into folds
   first, so a circle skirt's sides stayed out as flat wings. Cloth that reaches the floor rests on it.
5. **Finish**: Gauss-Seidel sweeps projecting each edge to its rest length, Chebyshev-accelerated, take back the
   stretch the settle's gravity left in cloth resting on the body and the local strain (`lengths`,
   `kitsuke.cloth.restore_lengths`; optionally after a few global relaxation steps without gravity,
   `lengths.finish_iterations`, 0 by default). The sweeps also pull each pattern stroke back within
   `tethers.reach_m` of its body stroke where the settle let it hang farther (one-sided tethers,
   `kitsuke.cloth.Tethers`), so the strokes are met and the rest drapes freely.
6. **Untangle** (`kitsuke.cloth.untangle`, also run at the end of step 3, before a hold band is pinned):
   triangles still folded over their neighbours are opened by relaxing only a few rings of cloth around them,
   the rest of the garment held still (`untangle.rounds`); the stroke tethers still apply.
7. **Polish** (`kitsuke.cloth.polish_refined`, through `_polish_step`): an L-BFGS minimisation of one energy over
   the garment (edge springs with a barrier past 2 % strain, quadratic bending, contact planes, the stroke
   tethers, the layer order) lets compressed cloth buckle into wrinkles and spreads stretch; strain-limit sweeps
   then pull the few edges it left over 4.5 % back to it; where triangles are left folded, the cloth around them
   is refined (adaptive sqrt(3), up to `polish.levels`) and polished again, so the crease becomes a
   wrinkle of finer triangles; the untangle opens what is still folded. The result is kept only where it is
   better: lower max strain, and mean strain, stroke residual, folds and layer order no worse than before or
   than the targets (1 %, 10 mm, none, the layer gap). While the max strain is over 5 %, a second pass. A refined
   garment has more faces than its pattern mesh (`DressedGarment.faces`).

Steps 2-6 (and 4b) are stages of `_stages` (`stage(model, state, collider, config) -> stats`, each given the pins
it holds as a view of the state, timed, announced to `progress` and checked for non-finite positions); their
settings are `WrapParams`' groups (`wrap_settings`), one per stage.

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
from ..cloth import BodyCollider, ClothModel, ClothParams, ClothState, RefinedPolish, Tethers
from ..errors import ComputationError, InputError
from ..geometry import TriMesh
from ..geometry.surface import Surface
from ..metrics import Girth, QualityReport, QualityTargets, garment_girth, quality_report, strain
from ..pattern import Pattern, PatternMesh, face_layers, mesh_pattern
from ._bridge import bridged, spans_legs
from ._fit_height import fitting_lift
from ._gather import Gather, gathered_rest
from ._laid import lay_at_placement
from ._mend import MendStats, mend_tears
from ._place import StrokeTrack, place_strokes
from ._polish_step import polish_step
from ._refined import pieces_contiguous, remap_track, reorder_state
from ._stages import (
    Closing,
    Draping,
    Finishing,
    Growing,
    Settling,
    StageLog,
    Untangling,
    check_finite,
    close_stage,
    drape_stage,
    finish_stage,
    grow_stage,
    run_stage,
    settle_stage,
    untangle_stage,
)
from ._weld import repair_corners, weld
from .outcome import SHORT_SAID, body_axis, on_body_failures, target_misses, wrong_side_pieces
from .strokes import Strokes, resolve_strokes, slivers_left_out
from .wrap_settings import SEW_FRAMES, WrapParams


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
    loose_strokes : ids of the strokes not held to their body strokes after the settle (`TetherSettings.slack_m`).
    gathers : the seams whose longer side was gathered onto the shorter (`WrapParams.gather`): the model's rest
        shape is gathered there, and strain is measured against it.
    laid : pieces laid at their placement instead of grown (`GrowSettings.laid`; by the wrap itself where growth
        took them to the wrong side of the body or failed otherwise, the earlier tries' time in timings["first
        try"]). sewn : its close sewed the seams (`CloseSettings.sew_frames`; by the wrap itself when every earlier
        try failed, `sew_on_failure`). redone_after : why the wrap dressed the garment once more
        (`GrowSettings.relay`, `CloseSettings.sew_on_failure`): the first try's failure, one line; "" when the
        first try was kept.
    left_out : {piece name: mean width, cm} of the slivers left out of the wrap (`strokes.slivers_left_out`).
    rings : growth rings. mend : what `_mend.mend_tears` did after the close (rounds, torn edges before and
        after). polished : the polish's result was kept (`PolishSettings.rounds`). timings : seconds per step
        ("mesh", "resolve", "place", "grow", "close", "settle", "finish", "untangle", "polish", "wrap" = all of
        them, "report").
    report : the SPEC §6 quality report against the body. girth : the horizontal loop of cloth through its worst
        strained edge against the body's girth there (`kitsuke.metrics.garment_girth`: a garment cut smaller than
        the body must stretch), or None where that cut does not go round the body. fits_higher_m : where that loop
        is cut smaller than the body, how far up the garment would fit (`_fit_height.fitting_lift`; 0: nowhere
        within reach, or it hangs from the shoulders): its strokes were drawn too low.
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
    gathers: list[Gather] = field(default_factory=list)
    laid: list[str] = field(default_factory=list)
    left_out: dict[str, float] = field(default_factory=dict)
    sewn: bool = False
    redone_after: str = ""
    rings: int = 0
    mend: MendStats = field(default_factory=MendStats)
    polished: bool = False
    timings: dict[str, float] = field(default_factory=dict)
    report: QualityReport | None = None
    girth: Girth | None = None
    fits_higher_m: float = 0.0

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
            "gathered_seams": [dataclasses.asdict(g) | {"ratio": round(g.ratio, 4)} for g in self.gathers],
            "laid_pieces": list(self.laid),
            "left_out_pieces": {name: {"mean_width_mm": round(w * 10.0, 3)} for name, w in self.left_out.items()},
            "seams_sewn": self.sewn,
            "redone_after": self.redone_after,
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
            "girth_at_worst_strain": None if self.girth is None else self.girth.to_dict(),
            "fits_higher_m": round(self.fits_higher_m, 3),
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


#: The quality targets' max edge strain (QualityTargets): the polish runs another pass while the garment is over it.
MAX_STRAIN_TARGET = QualityTargets().max_strain


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
    say = progress or (lambda _stage: None)
    t0 = time.perf_counter()
    prep = _prepare(body, garment, strokes, pattern, p, collider, say)
    first = _dress(prep, p, report, say, t0, dict(prep.timings))
    if not check:
        return first
    failure = _failure(first, prep)
    if failure is None:
        return first
    # The relay (`GrowSettings.relay`, `CloseSettings.sew_on_failure`): chains of at most three tries, which bounds
    # its time (a top over a tiered skirt laid piece by piece took eight tries): the garment as grown (the first
    # try) or sewn, then the pieces growth took to the wrong side laid at their placement, then every piece laid.
    chains: list[tuple[WrapParams, DressedGarment | None]] = [(p, first)]
    if p.close.sew_on_failure and not p.close.sew_frames:
        chains.append((p.changed({"close.sew_frames": SEW_FRAMES, "close.sew_on_failure": False}), None))
    for q, tried in chains:
        if tried is None:
            say("sewing the seams")
            t_try = time.perf_counter()
            tried = _try(prep, q, report, say, t_try)
        for every in (False, True, None):
            if tried is None:  # a stage of that try went non-finite: its chain ends
                break
            if tried is not first and _failure(tried, prep) is None:
                tried.timings["first try"] = t_try - t0  # the earlier tries' time
                tried.redone_after = failure.message
                return tried
            relay = None if every is None else _relayed(q, tried, prep.mesh, every)
            if relay is None:
                break
            q, what = relay
            say(what)
            t_try = time.perf_counter()
            tried = _try(prep, q, report, say, t_try)
    first.timings["wrap"] = time.perf_counter() - t0  # every try
    raise failure


@dataclass
class _Prepared:
    """What every try of one wrap shares: the body, the meshed garment and the strokes resolved on the body."""

    body: object
    mesh: TriMesh
    pm: PatternMesh
    pattern: Pattern | None
    strokes: Strokes
    collider: BodyCollider
    surface: Surface
    left_out: dict[str, float]
    timings: dict[str, float]


def _prepare(body, garment, strokes: Strokes, pattern, p: WrapParams, collider, say) -> _Prepared:
    """Mesh the garment (a Pattern, slivers left out) and put its strokes on the body; see `wrap`."""
    timings: dict[str, float] = {}
    t0 = time.perf_counter()
    say("meshing")
    left_out: dict[str, float] = {}
    if isinstance(garment, Pattern):
        # Slivers mesh into needle triangles a fraction of a millimetre across that any wrinkle tears (GarmentCode's
        # sampler cuts trouser cuffs 0.25 mm tall: an edge at 3.6x its length failed the wrap); cloth that narrow
        # is no part of the garment anyone sees.
        left_out = slivers_left_out(strokes, garment)
        pattern = garment.without(left_out) if left_out else garment
        pm = mesh_pattern(pattern, edge_length=p.edge_length_cm)
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
    return _Prepared(body, mesh, pm, pattern, strokes, collider, surface, left_out, timings)


def _failure(garment: DressedGarment, prep: _Prepared) -> ComputationError | None:
    """The wrap's failure when `garment` is not a garment on the body (`outcome.on_body_failures`), else None."""
    bad = on_body_failures(garment, prep.body, surface=prep.surface)
    if not bad:
        return None
    more = f" (and {len(bad) - 1} more)" if len(bad) > 1 else ""
    return ComputationError("wrap", f"not a garment on the body: {bad[0]}{more}", result=garment)


def _relayed(p: WrapParams, failed: DressedGarment, mesh: TriMesh, every: bool) -> tuple[WrapParams, str] | None:
    """The relay's next try after `failed`, dressed with `p`: its settings and what it does, one line; None when
    the relay is off or has no piece left to lay. The pieces without strokes that growth took to the wrong side
    of the body (`outcome.wrong_side_pieces`) are laid at their placement; with none (cloth torn round a limb, a
    piece off the body), or `every`, every placed piece is laid."""
    pm = failed.pattern_mesh
    if not p.grow.relay or "*" in p.grow.laid or not pm.placed.any():
        return None
    wrong = [] if every else [pm.piece_names[k] for k, _ in wrong_side_pieces(failed, mesh)]
    wrong = [name for name in wrong if name not in failed.laid]
    laid = tuple(p.grow.laid) + tuple(wrong) if wrong else ("*",)
    return p.changed({"grow.laid": laid}), f"laying {', '.join(wrong) or 'every piece'} at the placement"


def _try(prep: _Prepared, p: WrapParams, report: bool, say, t0: float) -> DressedGarment | None:
    """One more try of the relay; None when a stage of it went non-finite."""
    try:
        return _dress(prep, p, report, say, t0, {})
    except ComputationError:
        return None


def _dress(prep: _Prepared, p: WrapParams, report: bool, say, t0: float, timings: dict[str, float]) -> DressedGarment:
    """One try of the wrap (steps 1-7, the report), not checked; `t0` its start (timings["wrap"] from it)."""
    body, mesh, pm, pattern, strokes = prep.body, prep.mesh, prep.pm, prep.pattern, prep.strokes
    collider, surface, left_out = prep.collider, prep.surface, prep.left_out
    say("placing the pieces")
    t2 = time.perf_counter()
    welded = weld(pm)
    shaping = collider  # growth, close and mend run against the body with its leg gap filled, for a skirt
    hang = p.grow.hang
    gap = leg_gap(mesh) if p.grow.bridge_legs is not False else None
    if gap is not None and (p.grow.bridge_legs or spans_legs(pm, welded, gap.crotch_y)):
        shaping = bridged(collider, gap)
        hang = hang or p.grow.skirt_hang
    placements = None if pattern is None else {pc.name: pc.placement for pc in pattern.pieces if pc.placement}
    placement = place_strokes(pm, welded, strokes, surface, collider, lift_m=p.grow.lift_m, placements=placements)
    seed_pins = placement.placed.copy()  # the stroke triangles' vertices, held while the garment grows
    unknown = sorted(set(p.grow.laid) - set(pm.piece_names) - {"*"})
    if unknown:
        raise InputError(f"grow.laid names no piece {', '.join(map(repr, unknown))} of pattern {pm.name!r}")
    every = "*" in p.grow.laid
    laid = [k for k, name in enumerate(pm.piece_names) if (every or name in p.grow.laid) and pm.placed[k]]
    if laid:
        placement = lay_at_placement(pm, welded, placement, laid, body_axis(mesh))
    grow_params = dataclasses.replace(p.cloth, gravity_step_m=0.0)
    layer = face_layers(pm.layers, pm.piece_names, welded.piece_faces, welded.rest_corners * 100.0)
    # Seams of unequal sides gather the longer one: the model's rest shape (its uv stays the pattern's).
    g = p.gather
    rest, gathers = gathered_rest(pm, welded, min_difference=g.min_difference, min_cm=g.min_cm, depth_cm=g.depth_cm)
    model = ClothModel.from_corners(
        welded.faces, rest, n_vertices=welded.n_vertices, params=grow_params, face_layer=layer
    )
    state = ClothState.new(model, placement.positions, face_active=placement.seed_faces)
    free = np.zeros(model.n_vertices, dtype=bool)
    timings["place"] = time.perf_counter() - t2
    log = StageLog("wrap", say, timings)

    # Step 2: the seed faces' vertices are placed; faces whose three vertices are placed join at once.
    growing = Growing(p.grow, hang, placement.placed.copy())
    grown = run_stage(
        log, "growing the cloth", grow_stage, model, state, shaping, growing, pinned=seed_pins, timing="grow"
    )
    if not state.face_active.all():
        missing = np.flatnonzero(~state.face_active)
        piece_of = np.searchsorted(welded.piece_faces[:, 1], missing, side="right")
        names = sorted({pm.piece_names[i] for i in np.unique(piece_of)})
        raise InputError(
            f"no stroke reaches piece(s) {', '.join(names)}: draw a stroke on them or sew them to a piece that has one",
            strokes.source or None,
        )

    # Step 3, the close: stroke pins released so that collision reaches the stroke triangles too; they are only held
    # softly towards where the strokes put them (`close.stroke_hold`). The mend regrows torn cloth and closes again.
    mended = MendStats()
    legs = None if gap is None or shaping is not collider else gap.crotch_y  # a skirt's legs are bridged as one
    closing = Closing(p.close, held=seed_pins, targets=state.positions.copy(), legs_below_y=legs)
    if p.close.iterations:
        run_stage(log, "closing the seams", close_stage, model, state, shaping, closing, pinned=free, timing="close")
        if p.close.tear_strain is not None and p.close.mend_rounds:

            def mend(model: ClothModel, state: ClothState, collider: BodyCollider, config: Closing) -> dict:
                stats = mend_tears(
                    model,
                    state,
                    placement.seed_faces,
                    lambda placed: grow_stage(model, state, collider, dataclasses.replace(growing, placed=placed)),
                    lambda: close_stage(model, state, collider, config),
                    tear_strain=p.close.tear_strain,
                    rounds=p.close.mend_rounds,
                )
                return dataclasses.asdict(stats)

            mended = MendStats(
                **run_stage(log, "mending tears", mend, model, state, shaping, closing, pinned=free, timing="close")
            )
    # Before the hold band is pinned: a fold inside the band could not open later.
    run_stage(
        log,
        "untangling after the close",
        untangle_stage,
        model,
        state,
        shaping,
        Untangling(p.untangle.rounds),
        pinned=free,
        timing="close",
    )

    # Step 4: gravity, the strokes let go (or held) and a hold band pinned.
    settle = model.with_params(p.cloth)
    pins = free.copy() if p.settle.release_strokes else seed_pins.copy()
    band = np.zeros(model.n_vertices, dtype=bool)
    if p.settle.hold_band_m is not None:
        band = _band_held(body, mesh, state, p.settle.hold_band_m, p.settle.hold_reach_m) & ~pins
        pins |= band
    settle_collider = shaping if p.settle.method == "jacobi" else collider
    settling = Settling(p.settle, p.cloth, p.close.contact_weight)
    run_stage(log, "settling", settle_stage, model, state, settle_collider, settling, pinned=pins, timing="settle")

    # Steps 5-7. The band holds the cloth up against gravity; the finish and the length restoration have none, so
    # they let it go (pinned where the close left it, the kimono's back under the obi kept 5-20 % strain).
    unheld = pins & ~band
    tethers = None
    # A stroke whose cloth settled far from it is not pulled back: where the pattern cannot lie along the stroke
    # without stretching, the pull tears it. Its residual is reported instead.
    settled = np.array([tr.residual_m(state.positions, model.faces) for tr in placement.tracks])
    loose = settled > p.tethers.slack_m
    if p.tethers.reach_m is not None and not loose.all():
        tethers = _tethers(placement.tracks, loose, model.faces, p.tethers.reach_m)
    # After the strokes are judged: the finish's tethers pull back a stroke the falling cloth took with it.
    run_stage(log, "draping", drape_stage, model, state, collider, Draping(p.drape), pinned=pins, timing="drape")

    def finish_and_polish(state: ClothState, tethers: Tethers | None, loose: np.ndarray) -> _Finished:
        """Steps 5-7 from the settled `state`."""
        finishing = Finishing(p.lengths, p.close, tethers)
        run_stage(
            log, "restoring lengths", finish_stage, settle, state, collider, finishing, pinned=unheld, timing="finish"
        )
        # Without gravity, like the length restoration: the band is let go here too (a fold the sweeps left in it,
        # where the kimono's layers lie pressed on each other, could not open otherwise).
        untangling = Untangling(p.untangle.rounds, p.untangle.bend, tethers=tethers)
        run_stage(
            log, "untangling", untangle_stage, settle, state, collider, untangling, pinned=unheld, timing="untangle"
        )
        log.say("polishing")
        t_polish = time.perf_counter()
        done = _polish_passes(settle, state, collider, p, welded, placement.tracks, tethers, loose, unheld)
        check_finite(done.state, "wrap: polish")
        timings["polish"] = timings.get("polish", 0.0) + time.perf_counter() - t_polish
        return done

    settled_state = state.copy() if tethers is not None else None
    done = finish_and_polish(state, tethers, loose)
    held = strain(done.state.positions, done.model.edges, done.model.rest_lengths).max
    if settled_state is not None and held > p.tethers.strain:
        # Strokes the cloth cannot lie along without stretching (a shirt's strokes drawn 2 cm below where its
        # shoulders can go: 46 % max strain held there, 4.6 % let go): the same steps without their tethers, kept
        # when they halve the max strain and end within twice its target; the strokes are then reported loose.
        log.say("trying without the stroke tethers")
        free_done = finish_and_polish(settled_state, None, np.ones_like(loose))
        loose_max = strain(free_done.state.positions, free_done.model.edges, free_done.model.rest_lengths).max
        if loose_max < 0.5 * held and loose_max <= 2 * MAX_STRAIN_TARGET:
            done, loose = free_done, np.ones_like(loose)
    t6 = time.perf_counter()
    timings["wrap"] = t6 - t0

    state, out_model, tracks = done.state, done.model, done.tracks
    residual = np.array([tr.residual_m(state.positions, out_model.faces) for tr in tracks])
    ratio = np.array([tr.body_length_m / tr.pattern_length_m for tr in placement.tracks])
    result = DressedGarment(
        name=pm.name,
        piece_names=list(pm.piece_names),
        piece_faces=done.piece_faces,
        positions=state.positions,
        faces=out_model.faces,
        corner_uv=done.corner_uv,
        pattern_vertex=welded.vertex_of,
        pattern_mesh=pm,
        model=out_model,
        pinned=np.concatenate([pins, np.zeros(out_model.n_vertices - len(pins), dtype=bool)]),
        stroke_ids=[tr.id for tr in placement.tracks],
        stroke_residual_m=residual,
        stroke_length_ratio=ratio,
        tracks=tracks,
        loose_strokes=[tr.id for tr, far in zip(placement.tracks, loose, strict=True) if far],
        gathers=gathers,
        laid=[pm.piece_names[k] for k in laid],
        left_out=left_out,
        sewn=bool(p.close.sew_frames),
        rings=grown["rings"],
        polished=done.polished,
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
        if result.report.strain_worst_edges:
            worst = out_model.edges[result.report.strain_worst_edges[0]]
            at = state.positions[worst].mean(axis=0)
            result.girth = garment_girth(state.positions, out_model.faces, out_model.rest_corners, mesh, at)
            if result.girth is not None and result.girth.short >= SHORT_SAID:
                result.fits_higher_m = fitting_lift(state.positions, out_model.faces, out_model.rest_corners, surface)
        timings["report"] = time.perf_counter() - t6
    return result


def _tethers(tracks: list[StrokeTrack], loose: np.ndarray, faces: np.ndarray, reach_m: float) -> Tethers:
    """The one-sided pulls keeping each stroke not `loose` within `reach_m` of its body stroke."""
    return Tethers.from_polylines(
        [(tr.faces, tr.bary, tr.body_path) for tr, far in zip(tracks, loose, strict=True) if not far], faces, reach_m
    )


@dataclass
class _Finished:
    """The garment after steps 5-7: its state and model (refined where the polish folded), the pieces' face ranges
    and corner uv of that model, the stroke tracks on it, and whether a polish was kept."""

    state: ClothState
    model: ClothModel
    piece_faces: np.ndarray
    corner_uv: np.ndarray
    tracks: list[StrokeTrack]
    polished: bool


def _polish_passes(
    model: ClothModel,
    state: ClothState,
    collider: BodyCollider,
    p: WrapParams,
    welded,
    tracks: list[StrokeTrack],
    tethers: Tethers | None,
    loose: np.ndarray,
    unheld: np.ndarray,
) -> _Finished:
    """Step 7: up to `polish.passes` polishes (`_polish_step`; a later one only while the max strain is over
    MAX_STRAIN_TARGET: it starts from the better cloth and takes another path to the buckles), each kept only where
    better. A refining polish gives the garment new faces: the state, pieces, uv and stroke tracks follow them.
    `unheld` (V,) bool: the pins the polish holds."""
    out = _Finished(state, model, welded.piece_faces, welded.rest_corners, tracks, False)
    # The stroke samples of the garment as it is, or of the refined polish rp made of it (moved onto its new faces:
    # between their old corners they lie off the refined surface).
    refined_tracks: dict[int, tuple] = {}  # id(rp) -> (its PieceOrdered, the tracks on it): made once, used twice

    def on_refined(rp: RefinedPolish) -> tuple:
        if id(rp) not in refined_tracks:
            ordered = pieces_contiguous(rp, out.piece_faces)
            refined_tracks.clear()
            refined_tracks[id(rp)] = (
                ordered,
                [remap_track(tr, out.corner_uv, out.piece_faces, ordered) for tr in out.tracks],
            )
        return refined_tracks[id(rp)]

    def residual_of(positions: np.ndarray, rp: RefinedPolish | None = None) -> np.ndarray:
        if rp is None or not rp.levels:
            return np.array([tr.residual_m(positions, out.model.faces) for tr in out.tracks])
        ordered, moved = on_refined(rp)
        return np.array([tr.residual_m(positions, ordered.model.faces) for tr in moved])

    settings = p.polish_settings()
    passes = 0
    level = pending = None
    while settings.rounds and passes < settings.passes:
        if passes and strain(out.state.positions, out.model.edges, out.model.rest_lengths).max <= MAX_STRAIN_TARGET:
            break
        passes += 1
        held = np.concatenate([unheld, np.zeros(out.model.n_vertices - len(unheld), dtype=bool)])
        kept, rp = polish_step(
            out.model,
            out.state.holding(held),
            collider,
            settings,
            tethers=tethers,
            corner_data={"uv": out.corner_uv},
            residual_of=residual_of,
            level=level,
            pending=pending,
        )
        if not kept:
            break
        out.polished = True
        out.state = rp.state
        if rp.levels:
            ordered, out.tracks = on_refined(rp)
            out.state = reorder_state(out.state, ordered)
            level, pending = ordered.level, ordered.pending
            out.model, out.piece_faces, out.corner_uv = ordered.model, ordered.piece_faces, ordered.corner_uv
            if tethers is not None:  # a later pass holds the strokes on the refined faces
                tethers = _tethers(out.tracks, loose, out.model.faces, p.tethers.reach_m)
    return out
