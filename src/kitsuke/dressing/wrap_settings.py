"""The wrap's settings, grouped by the stage that reads them (`wrap`'s module docstring names the stages).

    from kitsuke.dressing import WrapParams
    params = WrapParams(edge_length_cm=2.5).changed({"polish.rounds": 0, "settle.iterations": 30})

Each group is a frozen dataclass whose defaults are the wrap's; what each default was measured to buy is in
BENCHMARKS.md ("Wrap settings"). Lengths in metres (`_m`) or centimetres (`_cm`), strains as fractions.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field, fields

from ..cloth import ClothParams
from ..errors import InputError, require_non_negative
from ._polish_step import PolishSettings


def _at_least(group: object, minimum: int, *names: str) -> None:
    for name in names:
        if getattr(group, name) < minimum:
            raise InputError(f"{type(group).__name__}.{name} must be >= {minimum}")


def _of_kind(name: str, default: object, value: object) -> object:
    """`value` for the setting `name` whose default is `default`, of the default's kind (an int given for a float
    becomes one); InputError otherwise. None and settings whose default is None or a settings group pass as they
    are: their own checks judge them."""
    if value is None or default is None or dataclasses.is_dataclass(default):
        return value
    if isinstance(default, tuple) and isinstance(value, str):  # names as text: "skirt_front, wb_front"
        value = tuple(v.strip() for v in value.split(",") if v.strip())
    if isinstance(default, bool):
        ok = isinstance(value, bool)
        kind = "True or False"
    elif isinstance(default, int):
        ok = isinstance(value, int) and not isinstance(value, bool)
        kind = "a whole number"
    elif isinstance(default, float):
        ok = isinstance(value, (int, float)) and not isinstance(value, bool)
        value = float(value) if ok else value
        kind = "a number"
    else:
        ok = isinstance(value, type(default))
        kind = f"a {type(default).__name__}"
    if not ok:
        raise InputError(f"wrap setting {name} takes {kind}, got {value!r}")
    return value


@dataclass(frozen=True)
class GatherSettings:
    """Before growth: a seam whose sides differ in length gathers its longer side (`kitsuke.dressing._gather`).

    min_difference, min_cm : sides differing by more than this share of the longer and by more than this many cm
        are gathered; others share their difference between the two sides (a 1.5 mm stitch against a 0.7 mm one
        is a rounding of the design, not a gather: gathered, it shrank the bodice round it by half and tore it).
    depth_cm : how far into the gathered piece its rest shape is shortened along the seam, easing from the seam's
        ratio to none, cm; 0 gathers nothing.
    """

    min_difference: float = 0.03
    min_cm: float = 1.0
    depth_cm: float = 8.0

    def __post_init__(self) -> None:
        require_non_negative(self, "GatherSettings", "min_difference", "min_cm", "depth_cm")


@dataclass(frozen=True)
class GrowSettings:
    """Steps 1-2, placing the stroke triangles and growing the rest of the garment from them.

    lift_m : the stroke triangles are laid this far off the body, metres (just outside the cloth's contact offset,
        so the first collision does not fight the placement).
    rings_per_relax : rings of triangles grown between relaxations (more is faster; fewer keeps the growth nearer
        the body).
    iterations : relaxation iterations (no gravity) after each group of rings.
    hang : how strongly cloth growing off the body turns down as it grows (0: straight on, the paper's growth;
        a kimono's sleeves need about 2 to hang as a bag below the arm instead of wrapping the forearm).
    skirt_hang : the hang of a garment that goes round both legs (where `bridge_legs` fills the gap between them)
        when `hang` is 0: a skirt's flare grown straight on sticks out as a flat disc.
    hang_clearance_m : cloth counts as off the body, and turns down as it grows, where both vertices of the edge it
        grows from are at least this far from the body, metres.
    bridge_legs : fill the gap between the legs (`kitsuke.body.legs`) for growing, closing and mending, so cloth
        grown over the hips drapes round both legs. None: when the garment has an opening below the crotch that
        goes round both legs (`_bridge.spans_legs`: a skirt's hem, not a trouser leg's); True / False: always /
        never.
    laid : names of pieces laid where the pattern's placement puts them (turned and moved as the stroked pieces
        were; a piece's stroke triangles stay on its strokes) instead of grown (`_laid`); "*": every piece with a
        placement. Pieces without a placement are grown.
    relay : when growth takes a piece without strokes to the wrong side of the body (`outcome.wrong_side_pieces`),
        dress once more with it laid (added to `laid`); when the wrap fails otherwise (`outcome.on_body_failures`:
        torn cloth, a piece off the body), or that try fails too, dress once more with every placed piece laid
        ("*"). At most two such tries follow a failed one, so the relay's time is bounded (with the sewn try of
        `CloseSettings.sew_on_failure` and its own two: six tries at most).
    """

    lift_m: float = 0.004
    rings_per_relax: int = 1
    iterations: int = 2
    hang: float = 0.0
    skirt_hang: float = 2.0
    hang_clearance_m: float = 0.03
    bridge_legs: bool | None = None
    laid: tuple[str, ...] = ()
    relay: bool = True

    def __post_init__(self) -> None:
        _at_least(self, 1, "rings_per_relax")
        _at_least(self, 0, "iterations")
        if not (self.lift_m >= 0 and self.hang_clearance_m >= 0):
            raise InputError("GrowSettings.lift_m and GrowSettings.hang_clearance_m must be >= 0 (metres)")
        require_non_negative(self, "GrowSettings", "hang", "skirt_hang")
        if self.bridge_legs not in (None, True, False):
            raise InputError(f"GrowSettings.bridge_legs must be None, True or False, got {self.bridge_legs!r}")
        if not all(isinstance(name, str) for name in self.laid):
            raise InputError("GrowSettings.laid must be piece names")


#: Frames of sewing when a failed wrap is dressed once more with its seams sewn (`CloseSettings.sew_on_failure`).
SEW_FRAMES = 90


@dataclass(frozen=True)
class CloseSettings:
    """Step 3, closing the seams: a global relaxation without gravity (`_solve.GlobalRelax`), then mending tears.

    iterations : most steps; it stops once the largest vertex move falls below `tolerance_m` (its first ~10 steps
        pull the seams shut; later ones only creep, which the length restoration does faster).
    tolerance_m : see iterations, metres.
    cg_iterations : most conjugate-gradient iterations of each step's contact solve (inexact is enough: each step
        starts from the last).
    stroke_hold : weight (relative to one triangle edge) pulling the stroke vertices towards where the strokes
        laid them; 0 lets the garment find its own rest around the strokes.
    contact_weight : weight (relative to one triangle edge) holding cloth that touches the body on its contact
        plane inside the solve (along the normal only, so it slides); 0: collision only after each solve.
    tear_strain : cloth round edges stretched more than this (1.0: twice their rest length) after the close is grown
        again from the closed cloth around it and closed again (`_mend`: growth took it round the wrong side of a
        limb); None: no mending.
    mend_rounds : most mending rounds.
    sew_frames : 0: the close is the global relaxation. Otherwise it sews instead (`kitsuke.cloth.sew`: the dynamic
        solver without gravity, each stretched edge's rest length shrinking `sew_shrink_m` a frame from its length
        to the pattern's, for at most this many frames): slower, and on the corpus its garments are more strained
        where the relaxation closes them well (two simple waistbands 2-4 -> 11-19 % max strain), but it never
        moves cloth far enough in one step to pass through a limb.
    sew_shrink_m : see sew_frames, metres per frame.
    sew_on_failure : a wrap that still fails after its relay (torn round a limb, off the body) is dressed once more
        with its seams sewn (`sew_frames` SEW_FRAMES): on 60 corpus designs, 12 of 21 failures written instead
        (out of target, 18-97 % max strain), no design worse.
    """

    iterations: int = 15
    tolerance_m: float = 2e-4
    cg_iterations: int = 10
    stroke_hold: float = 0.01
    contact_weight: float = 20.0
    tear_strain: float | None = 1.0
    mend_rounds: int = 3
    sew_frames: int = 0
    sew_shrink_m: float = 0.01
    sew_on_failure: bool = True

    def __post_init__(self) -> None:
        _at_least(self, 1, "cg_iterations")
        _at_least(self, 0, "iterations", "mend_rounds", "sew_frames")
        if not self.sew_shrink_m > 0:
            raise InputError("CloseSettings.sew_shrink_m must be > 0 metres per frame")
        if not (self.tolerance_m >= 0 and self.stroke_hold >= 0 and self.contact_weight >= 0):
            raise InputError("CloseSettings.tolerance_m, .stroke_hold and .contact_weight must be >= 0")
        if self.tear_strain is not None and not self.tear_strain > 0:
            raise InputError("CloseSettings.tear_strain must be > 0 (1.0 = twice the rest length) or None")


@dataclass(frozen=True)
class SettleSettings:
    """Step 4, settling under gravity with the stroke pins let go.

    method : "jacobi": `iterations` of the paper's relaxation (`kitsuke.cloth.relax`) with gravity, friction and
        collision; "global": `iterations` global steps (`_solve.gravity_settle`) with gravity `gravity_m` per step
        and static friction `stick_weight` (it does not stretch hanging cloth, at a little more time).
    iterations : iterations (jacobi) or steps (global).
    gravity_m : global: metres a free vertex falls per step.
    stick_weight : global: static friction (relative to one triangle edge) holding cloth that touches the body
        along it, so gravity does not slide the garment down the frictionless contact planes.
    release_strokes : let the stroke triangles go for the settle (the paper's); False keeps them where the
        strokes put them.
    hold_band_m : (low, high) heights in metres, or None: garment vertices in this band are pinned for the settle
        (a kimono's waist, held by the obi), where they are within `hold_reach_m` of the body and, on a rigged
        body, over the torso.
    hold_reach_m : see hold_band_m, metres.
    """

    method: str = "jacobi"
    iterations: int = 60
    gravity_m: float = 0.002
    stick_weight: float = 20.0
    release_strokes: bool = True
    hold_band_m: tuple[float, float] | None = None
    hold_reach_m: float = 0.05

    def __post_init__(self) -> None:
        _at_least(self, 0, "iterations")
        if self.method not in ("jacobi", "global"):
            raise InputError(f'SettleSettings.method must be "jacobi" or "global", got {self.method!r}')
        if not (self.gravity_m >= 0 and self.stick_weight >= 0 and self.hold_reach_m > 0):
            raise InputError("SettleSettings.gravity_m, .stick_weight >= 0 and .hold_reach_m > 0 (metres) required")
        if self.hold_band_m is not None and not (
            len(self.hold_band_m) == 2 and self.hold_band_m[0] < self.hold_band_m[1]
        ):
            raise InputError("SettleSettings.hold_band_m must be (low, high) with low < high, metres")


@dataclass(frozen=True)
class DrapeSettings:
    """Step 4b, the drape: cloth hanging off the body falls under gravity, in the dynamic solver
    (`kitsuke.cloth.step`, XPBD), while the cloth resting on the body is held where the settle left it. The static
    settle cannot let a flare fall: a circle skirt's sides stay out as flat wings, because falling means their
    hem gathering into folds, which a relaxation from a flat start never begins.

    seconds : simulated time (at 30 steps a second); 0 turns the drape off.
    hold_m : cloth closer to the body than this (metres) is held.
    min_hanging : the drape runs only when at least this share of the vertices lies `hanging_m` or more off the
        body (GarmentCode's shirt, 4 % of it 5 cm off, skips it; a circle skirt has 50-60 %).
    hanging_m : see min_hanging, metres.
    damping : fraction of the velocity lost per second.
    """

    seconds: float = 1.0
    hold_m: float = 0.01
    min_hanging: float = 0.10
    hanging_m: float = 0.05
    damping: float = 2.0

    def __post_init__(self) -> None:
        require_non_negative(self, "DrapeSettings", "seconds", "hold_m", "hanging_m", "damping")
        if not 0 <= self.min_hanging <= 1:
            raise InputError("DrapeSettings.min_hanging must be a share in [0, 1]")


@dataclass(frozen=True)
class LengthSettings:
    """Step 5, the finish: global steps without gravity (optional), then Gauss-Seidel sweeps projecting every
    edge to its rest length (`kitsuke.cloth.restore_lengths`), which take back the stretch the settle left.

    finish_iterations : global relaxation steps (contacts, no gravity) before the sweeps; 0: none.
    sweeps : length sweeps (collision every `collide_every`).
    chebyshev_rho : the sweeps' Chebyshev acceleration (`restore_lengths`' chebyshev_rho), or None.
    over_relaxation : omega of the sweeps (1: plain Gauss-Seidel; do not combine with the acceleration).
    collide_every : a collision update after this many sweeps.
    """

    finish_iterations: int = 0
    sweeps: int = 400
    chebyshev_rho: float | None = 0.99
    over_relaxation: float = 1.0
    collide_every: int = 4

    def __post_init__(self) -> None:
        _at_least(self, 1, "collide_every")
        _at_least(self, 0, "finish_iterations", "sweeps")
        if not 1.0 <= self.over_relaxation < 2.0:
            raise InputError("LengthSettings.over_relaxation must be in [1, 2)")
        if self.chebyshev_rho is not None and not 0.0 < self.chebyshev_rho < 1.0:
            raise InputError("LengthSettings.chebyshev_rho must be in (0, 1) or None")


@dataclass(frozen=True)
class TetherSettings:
    """How the strokes hold the settled garment (steps 5-7): one-sided pulls (`kitsuke.cloth.Tethers`).

    reach_m : every pattern stroke is kept within this distance of its body stroke, metres; None: no pull (the
        garment rests where gravity and its ease put it).
    slack_m : a stroke whose cloth the settle left farther than this from its body stroke is not tethered (the
        pattern cannot lie there without stretching); its residual is reported (`loose_strokes`), metres. A stroke
        the settle moved less far is pulled back: at 3 cm, strokes the settle had moved 3-5 cm were let go, missed
        their target or drifted on past 5 cm (GarmentCode designs of seeds 2718 and 4242, 3 -> 4 of 24 within
        targets, 13 -> 11 failed); at 5 cm, a fitted top's back stroke and a godet skirt's, moved 5-8 cm, ended
        26 mm off or strained (60 designs of seeds 2718, 4242, 6297, 3907, 7986: 20 -> 22 within targets at 8 cm,
        none fewer; one top over a pencil skirt out of target 22.7 -> 89.0 %, trousers 96.7 -> 53.5 %).
    strain : where the finish and polish with tethers leave an edge strained more than this, they run again
        without them, and the strokes are let go if that halves the max strain and ends within twice
        `MAX_STRAIN_TARGET`.
    """

    reach_m: float | None = 0.008
    slack_m: float = 0.08
    strain: float = 0.15

    def __post_init__(self) -> None:
        if self.reach_m is not None and not self.reach_m > 0:
            raise InputError("TetherSettings.reach_m must be > 0 (metres) or None")
        if not (self.slack_m > 0 and self.strain > 0):
            raise InputError("TetherSettings.slack_m and .strain must be > 0")


@dataclass(frozen=True)
class UntangleSettings:
    """Step 6 (also at the end of step 3): triangles folded over their neighbours opened by relaxing a few rings
    of cloth round them (`kitsuke.cloth.untangle`).

    rounds : most rounds (0: none); the polish's own untangle takes as many.
    bend : hinge stiffness of the untangle after the finish and of the polish's (the one after the close keeps
        `untangle`'s default): a stiff hinge opens the folds the sweeps laid flat into strained cloth.
    """

    rounds: int = 10
    bend: float = 0.1

    def __post_init__(self) -> None:
        _at_least(self, 0, "rounds")
        if not self.bend >= 0:
            raise InputError("UntangleSettings.bend must be >= 0")


#: The wrap's polish: as `PolishSettings` (also the re-wrap's and the drag's), with refinement where it folds.
WRAP_POLISH = PolishSettings(levels=5, max_folds=60, passes=2)


@dataclass(frozen=True)
class WrapParams:
    """Settings of `wrap`, one group per stage (see each group's docstring).

    edge_length_cm : target triangle edge length when `wrap` meshes a Pattern itself, cm.
    gather, grow, close, settle, drape, lengths, tethers, untangle, polish : the stages' settings. The polish (step 7;
        kept only where it is better, `_polish_step`) runs `polish.passes` passes while the max strain is over 5 %;
        its untangle follows `untangle`.
    cloth : ClothParams of the Jacobi relaxation (growth, the settle), the untangle and the returned model (a later
        drag). Strain limiting is off: with the seams still strained after growth it would drag the whole garment
        towards its supports in one iteration.
    """

    edge_length_cm: float = 1.5
    gather: GatherSettings = field(default_factory=GatherSettings)
    grow: GrowSettings = field(default_factory=GrowSettings)
    close: CloseSettings = field(default_factory=CloseSettings)
    settle: SettleSettings = field(default_factory=SettleSettings)
    drape: DrapeSettings = field(default_factory=DrapeSettings)
    lengths: LengthSettings = field(default_factory=LengthSettings)
    tethers: TetherSettings = field(default_factory=TetherSettings)
    untangle: UntangleSettings = field(default_factory=UntangleSettings)
    polish: PolishSettings = WRAP_POLISH
    cloth: ClothParams = field(default_factory=lambda: ClothParams(max_stretch=None))

    def __post_init__(self) -> None:
        if not self.edge_length_cm > 0:
            raise InputError("WrapParams.edge_length_cm must be > 0 (cm)")
        kinds = {
            "gather": GatherSettings,
            "grow": GrowSettings,
            "close": CloseSettings,
            "settle": SettleSettings,
            "drape": DrapeSettings,
            "lengths": LengthSettings,
            "tethers": TetherSettings,
            "untangle": UntangleSettings,
            "polish": PolishSettings,
            "cloth": ClothParams,
        }
        for name, kind in kinds.items():
            if not isinstance(getattr(self, name), kind):
                raise InputError(f"WrapParams.{name} must be a {kind.__name__}, got {getattr(self, name)!r}")

    @classmethod
    def strokes_held(cls, **groups) -> WrapParams:
        """Settings that make the strokes constraints rather than a starting placement: held firmly in the close
        and kept where they lie through the settle, so the garment hangs from them; strokes are then met within
        millimetres, and where they ask for more than the pattern gives, the cloth stretches instead. `groups` as
        for WrapParams."""
        base = cls(**groups)
        return base.changed({"close.stroke_hold": 1.0, "settle.release_strokes": False})

    def changed(self, values: dict[str, object]) -> WrapParams:
        """A copy with settings changed by dotted name: {"polish.rounds": 0, "edge_length_cm": 2.0}. Raises
        InputError for a name that is no setting, or a value of another kind than the setting's (a whole number
        for a count, a number for a quantity, True/False for a switch; None where the setting allows it)."""
        out = self
        names = {f.name for f in fields(self)}
        for name, value in values.items():
            group, _, key = name.partition(".")
            if group not in names:
                raise InputError(f"no wrap setting {name!r}: the groups are {', '.join(sorted(names))}")
            if not key:
                out = dataclasses.replace(out, **{group: _of_kind(name, getattr(out, group), value)})
                continue
            current = getattr(out, group)
            if not dataclasses.is_dataclass(current) or key not in {f.name for f in fields(current)}:
                known = ", ".join(f.name for f in fields(current)) if dataclasses.is_dataclass(current) else ""
                raise InputError(f"no wrap setting {name!r}" + (f": {group} has {known}" if known else ""))
            value = _of_kind(name, getattr(current, key), value)
            out = dataclasses.replace(out, **{group: dataclasses.replace(current, **{key: value})})
        return out

    def polish_settings(self) -> PolishSettings:
        """The polish's settings as the wrap runs it: its untangle follows `untangle`."""
        return dataclasses.replace(self.polish, untangle_rounds=self.untangle.rounds, untangle_bend=self.untangle.bend)
