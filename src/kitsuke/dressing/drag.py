"""Drag a dressed garment along the body surface, with pins (SPEC §4.1 item 6, §4.2 "Drag along the body").

    from kitsuke.dressing import DragSession
    session = DragSession(body, garment)       # a DressedGarment, or a GarmentFile read back from its OBJ
    session.pin([[0.0, 1.2, -0.15]])            # points, snapped to the nearest garment vertex
    session.grab([0.0, 1.0, 0.16])              # mouse down: the dependency graph and the weights
    session.move_to([0.0, 1.05, 0.16])          # the grab to a point on the body (or move_by(vector))
    session.release()                           # mouse up
    session.garment(), session.report()         # for write_garment_obj / write_garment_png; SPEC §6 quality

On grab (`_drag_field`):

1. **Dependency graph**: shortest paths over the cloth's edges (rest lengths: distances along the cloth) from the
   grabbed vertex. Edges leaving a pinned vertex are cut, so the drag does not propagate past pins, and cloth
   reached only through pins does not move at all (it is held while the grab lasts). Each vertex's weight comes
   from its distance to the grab d_g and to the nearest pin d_p: w = S(d_p / (d_g + d_p)), S(t) = 3t² - 2t³:
   1 at the grab, 0 at pins, and no kink at either (S' = 0; the paper's Fig. 11). Without pins w = 1 everywhere:
   the whole garment moves.
2. **The body part**: the grab's foot (its nearest body point) lies on a body part with an axis — the nearest of
   the body's capsules (torso, upper arm, forearm, thigh, shin, neck), through the centre of the body's cross
   section there (`body_axis`); without capsules (an unrigged body) the vertical through the body's slice.

Per update (one mouse move; `DragSession.update`):

3. **Move**: the drag d of the grab's foot, laid into the body's tangent plane, is read as a rigid motion of that
   body part's surface: its component around the axis turns about the axis (the angle that moves the grab's
   foot by it), the rest translates. Every vertex takes that motion's velocity at its position times its weight:
   a skirt dragged sideways turns around the waist, dragged up it rises; a sleeve dragged towards the elbow
   slides along the arm. Cloth on another limb (an arm, when the torso is turned) takes the translation but not
   the turn, faded over 10 cm of cloth (`_drag_field.turn_weights`): the kimono's body turns, its sleeves stay
   round the arms. Cloth touching the body takes the turn as a belt round it (along the surface's direction
   round the axis, at the grab's speed), not as a rigid turn that would drive a narrow hem into the ankles.
   Where that move brings a vertex near the body closer to it than it was (the body rises towards it: widening
   ahead, or a bowl) it is lifted back to its height above its foot (its nearest body point,
   which slides along the surface by the same vector: `_drag_kernels.trace_one`, a straight line on the unfolded
   triangles, equal to potpourri3d's geodesic tracer to 1e-10 m); where the body falls away beneath it
   (narrowing ahead, curving away) it goes straight on and bridges the gap, as cloth does. Cloth far from the
   body (beyond `far_m`) is only translated.

   Why not transport the drag vector along the body (the vector heat method, or turning it along the dependency
   graph by the body's normals, the paper's literal description) or along the cloth's own pattern frames?
   Parallel transport depends on the path where the surface is curved, and a garment is dragged along loops.
   Measured while developing this (a 30° turn of a skirt round the default body's hips; a 5 cm lift of the
   kimono): transport along body geodesics meets itself between the legs and turned the back of the skirt the
   wrong way (-12° at the buttocks); transport along the cloth's paths with the body's normals brought the two
   halves of the skirt to its back 100° apart (85 % strain there); transport in the pattern's frames suits the
   skirt (4.7 %) but pulls the kimono's back down over the shoulders while its sides go up (the armholes are
   cone points of the pattern: 69 % of the vertices within 5 +- 1.5 cm). The rigid motion of the body part,
   with the relaxation below: skirt 4.7 % max strain after the turn, 1.0 % after a lift; kimono 95 % within
   5 +- 1.5 cm, its mean strain 2.1 % -> 1.5 %.
4. **Relaxation**: `global_steps` of the global (local/global) relaxation of the wrap (`_solve.GlobalRelax`,
   factorised once per grab; the cloth touching the body held on its contact planes inside the solve, so the
   solve slides it along the body instead of pulling it in for collision to push back) and `relax_iterations` of
   the local one (`kitsuke.cloth.relax`), with collision;
   the pins, the grabbed vertex and the cloth the grab does not reach held; no gravity (the drag leaves the
   garment where the user puts it).
5. **Release**: more of both, the let-go point still held (shape matching has no friction without gravity, so a
   released rolled-up sleeve would otherwise spring back), then, where the max strain is above the 5 % target,
   the wrap's polish, refining where the drag bunched the cloth. Cloth held by pins and dragged farther than it
   can go without stretching is let go a little: if held the polish cannot meet the target, the let-go point may
   give, up to 1 cm, then 2 cm (`DragParams.release_give_m`), as real cloth springs back when let go.
   `release` says what it did (`ReleaseStats`: how far the point gave, new vertices, the max strain).
"""

from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from ..cloth import (
    BodyCollider,
    ClothModel,
    ClothParams,
    ClothState,
    RefinedPolish,
    Tethers,
    collide,
    relax,
    track,
)
from ..errors import InputError, require_non_negative
from ..geometry import TriMesh
from ..metrics import QualityReport, quality_report, strain
from . import _drag_kernels as K
from ._drag_field import body_axis, capsule_limbs, drag_weights, nearest_capsule, smooth_falloff, turn_weights
from ._polish_step import PolishSettings, polish_step
from ._refined import pieces_contiguous, reorder_state
from ._solve import GlobalRelax
from ._stages import Untangling, untangle_stage, until_still
from .export import GarmentFile, as_garment_file
from .wrap import DressedGarment, offset_as_dressed

#: Metres above the contact offset that still count as touching the body, for the contact planes of the drag's
#: global steps (collision leaves touching cloth exactly at the offset).
CONTACT_ROUNDOFF_M = 2e-4
#: Where the body's surface faces within asin(this) of the turn's axis (a shoulder's top, a foot's), its direction
#: round the axis is not defined: cloth there turns rigidly, blended in below this sine.
BELT_MIN_SIN = 0.5


@dataclass(frozen=True)
class DragParams:
    """Options of a drag; each with its unit and reason. "Skirt" and "kimono" below are the measurements of
    tests/dressing/test_drag.py (a 30° turn of a skirt; the wrap's kimono lifted 5 cm, dragged against pins).

    global_steps : global relaxation steps per update (`_solve.GlobalRelax`, factorised once per grab). The local
        (Jacobi) relaxation alone spreads a drag's distortion by one ring of triangles per iteration: the skirt
        kept 22 % max strain with 4 local iterations per update, 4.7 % with one global step and 2 local ones.
    relax_iterations : local relaxation iterations (`kitsuke.cloth.relax`: friction, un-flipping) per update,
        after the global steps. Without them the kimono's inverted triangles went from 11 to 23 in a lift.
    max_step_m : a move of the grab longer than this (metres) is split into updates of at most this length, so that
        the cloth relaxes along the way (a mouse moves millimetres per event; a drags file may jump further).
    near_m, far_m : metres. Cloth nearer the body than near_m keeps to it (lifted back to its height where the
        body rises towards it); cloth farther than far_m is only translated; smoothly blended between.
    falloff : "smooth" (S(t) = 3t² - 2t³: no kink at the grab or at a pin) or "linear" (t itself).
    turn_blend_m : metres of cloth over which a drag's turn about the grabbed body part fades out towards cloth on
        another limb (an arm, when the torso is turned: `_drag_field.turn_weights`). Cloth on a limb of its own
        takes the drag's translation but not the turn: turned about the torso, a kimono's sleeves would be swept
        through the arms (dragging the demo's kimono's front 1 cm sideways, no pins: 339 % max strain in the
        sleeve at the forearm after one update).
    contact_weight : weight (relative to one triangle edge) of the body contacts inside each global step: a vertex
        touching the body is held on the plane of its contact (normal direction only, so cloth slides; released
        where the solve pulls it off), as in the wrap's close (`CloseSettings.contact_weight`), but only where the
        cloth touches the body (the close also draws in cloth within the contact distance). 0 applies collision
        only after each step, which fights the step where it pulls cloth round a leg into the body: the 2.5 cm
        kimono dragged 10 cm up and down three times (benchmarks/bench_drag.py) tore round the shins, 206 % max
        strain and 2.9 % mean after the release; 28 % / 0.73 % with 20 (it was dressed at 26 % / 0.55 %), 30 % /
        0.94 % with 10, 159 % / 2.0 % with 5. The max strain after the release in the scenarios of
        tests/dressing/test_drag.py, for weights 0 (5 mm clamp, 40 release steps: the settings before the
        planes) / 5 (5 mm, 80) / 10 (1 cm, 80) / 20 (1 cm, 80): skirt turned 4.7 / 3.6 / 4.2 / 4.5 %; kimono
        lifted 32 / 31 / 33 / 26 %, pinned 53 / 52 / 55 / 61 %, sleeve rolled up 43 / 44 / 44 / 67 % (at the
        bunched cuff; the kimono's mean strain 0.6-0.9 % in all). 20 is the weight that kept the mean strain
        under 1 % after every rough drag tried.
    contact_iterations : most conjugate-gradient iterations of each contacted global step (preconditioned by the
        factorised step without contacts; measured: 5 and 40 give the same garment).
    max_relax_move_m : a global relaxation step moves no vertex farther than this, metres. The global solve sees
        the body only through the contact planes of cloth already touching it: without planes and unclamped, it
        pulled kimono cloth through a shin in one step (an edge at 326 % strain). With planes (weight 10), 1 cm (less
        than the thinnest part a garment hangs on) left the rolled-up sleeve at 44 % max strain, 5 mm at 53 %.
    release_steps : most global relaxation steps when the grab is released (the grabbed vertex stays where it was
        left, the cloth the grab did not reach still held); they stop once no vertex moves more than
        `release_tolerance_m`. The skirt ended at 21 % max strain without them (60 local iterations instead), 4.7 %
        with 40 (without contact planes, where 80 tore the kimono at a shin); with the planes, 40 left the turned
        skirt at 12 %, 80 at 4.2 %.
    release_relax_iterations : local relaxation iterations after those (un-flipping what the drag folded).
    release_untangle_rounds : most rounds of `kitsuke.cloth.untangle` after those: folds the drag left (a sleeve
        rolled up bunches its cloth) are opened locally, the held cloth kept still (0: none).
    release_untangle_iterations : relaxation iterations of each untangle round. A fold pressed between arm and
        torso needs more than the wrap's 30 (after a 5 cm lift of the demo's kimono: one armpit triangle left
        folded with 30, none with 60).
    release_tolerance_m : metres, see release_steps.
    release_polish_rounds, release_polish_iterations : after those, the wrap's polish (`_polish_step`), the held
        cloth still held, kept only where it lowers the max strain with nothing folded: the drag's relaxation is
        tuned, not converged (measured on the skirt turned 30 degrees: 5.5 -> 2.6 % max strain; 0: none).
    release_polish_levels, release_polish_max_folds : its refinement where it folds (`polish_refined`): cloth a
        drag bunched (a sleeve rolled up, a front lifted against a pinned back) buckles into wrinkles of finer
        triangles instead of staying compressed (measured on the demo's kimono, sleeve rolled up 10 cm: 35.9 ->
        4.8 % max strain; its outer front lifted 6 cm with the back pinned: 4.8 % with 1 cm of give, where
        without refinement it took 2 cm). The session then goes on with the refined garment: old vertices keep
        their indices (pins hold), new ones follow; 0 levels: the garment keeps its triangles.
    release_polish_above : the polish runs only where the max edge strain after the release is above this (issue
        3's 5 %): a drag that left the garment within the target is left as the drag made it.
    release_give_m : metres, tried in turn when the release's polish with the let-go point held still leaves the
        max strain above `release_polish_above`: the point may then give, within that distance of where it was
        let go (a tether, `kitsuke.cloth.Tethers`), and the first that meets the target is kept (else the lowest
        max strain). Cloth dragged farther than it can go without stretching springs back that far when let go,
        as real cloth does (measured on the demo's kimono, its front lifted 6 cm with the back pinned: 8.1 % max
        strain held, 4.8 % with 1 cm of give; it gave 0.97 cm). () : never.
    max_pick_distance_m : a grab or pin point may lie at most this far from a garment vertex, metres.
    max_target_distance_m : a target of the grab may lie at most this far from the body surface, metres.
    max_crossings : most body triangle edges a foot may cross in one update (a bound on the surface walk).
    cloth : ClothParams of the relaxation: no gravity (a drag leaves the garment where the user puts it; gravity
        would keep pulling it down between updates), hence no strain limiting (it works with gravity). Where its
        contact offset is ClothParams' default, a DressedGarment is dragged at the offset it was dressed with.
    """

    global_steps: int = 1
    relax_iterations: int = 2
    max_step_m: float = 0.01
    near_m: float = 0.015
    far_m: float = 0.04
    falloff: Literal["smooth", "linear"] = "smooth"
    turn_blend_m: float = 0.1
    contact_weight: float = 20.0
    contact_iterations: int = 5
    max_relax_move_m: float = 0.01
    release_steps: int = 80
    release_relax_iterations: int = 40
    release_untangle_rounds: int = 10
    release_untangle_iterations: int = 60
    release_tolerance_m: float = 5e-5
    release_polish_rounds: int = 8
    release_polish_iterations: int = 40
    release_polish_above: float = 0.05
    release_polish_levels: int = 5
    release_polish_max_folds: int = 60
    release_give_m: tuple[float, ...] = (0.01, 0.02)
    max_pick_distance_m: float = 0.05
    max_target_distance_m: float = 0.10
    max_crossings: int = 256
    cloth: ClothParams = field(default_factory=lambda: ClothParams(gravity_step_m=0.0, max_stretch=None))

    def __post_init__(self) -> None:
        for name in (
            "global_steps",
            "relax_iterations",
            "release_steps",
            "release_relax_iterations",
            "release_untangle_rounds",
            "release_polish_rounds",
            "release_polish_levels",
            "release_polish_max_folds",
            "max_crossings",
        ):
            v = getattr(self, name)
            if not isinstance(v, int) or v < 0:
                raise InputError(f"drag parameter {name} must be an integer >= 0, got {v!r}")
        for name in ("release_untangle_iterations", "contact_iterations", "release_polish_iterations"):
            v = getattr(self, name)
            if not isinstance(v, int) or v < 1:
                raise InputError(f"drag parameter {name} must be an integer >= 1, got {v!r}")
        if not (math.isfinite(self.release_polish_above) and self.release_polish_above >= 0):
            raise InputError(
                f"drag parameter release_polish_above must be a strain >= 0, got {self.release_polish_above!r}"
            )
        for name in (
            "max_step_m",
            "max_pick_distance_m",
            "max_target_distance_m",
            "release_tolerance_m",
            "max_relax_move_m",
            "turn_blend_m",
        ):
            v = getattr(self, name)
            if not (math.isfinite(v) and v > 0):
                raise InputError(f"drag parameter {name} must be a finite number > 0, got {v!r}")
        give = self.release_give_m
        if not (
            isinstance(give, tuple)
            and all(isinstance(g, int | float) and math.isfinite(g) and g > 0 for g in give)
            and list(give) == sorted(give)
        ):
            raise InputError(f"drag parameter release_give_m must be a tuple of increasing metres > 0, got {give!r}")
        require_non_negative(self, "drag parameter", "contact_weight")
        if not (0 <= self.near_m < self.far_m and math.isfinite(self.far_m)):
            raise InputError("drag parameters need 0 <= near_m < far_m (metres)")
        if self.falloff not in ("smooth", "linear"):
            raise InputError(f"drag falloff must be 'smooth' or 'linear', got {self.falloff!r}")
        if not isinstance(self.cloth, ClothParams):
            raise InputError("drag parameter cloth must be a ClothParams")


@dataclass
class Grab:
    """A grab (mouse down): the grabbed vertex, the dependency graph and the weights.

    vertex : the grabbed garment vertex.
    weight : (V,) float64 in [0, 1], how much of the drag each vertex takes (1 at the grab, 0 at pins and beyond).
    distance_grab_m, distance_pin_m : (V,) float64, metres along the cloth (rest lengths) to the grab (through no
        pin; inf where only pins lead) and to the nearest pin (inf without pins).
    parent : (V,) int64, each vertex's parent in the dependency graph (-1 at the grab and where unreached).
    held : (V,) bool, the vertices the grab does not move (pins and the cloth beyond them), held while it lasts.
    axis, axis_point : (3,) float64, the unit axis of the body part under the grab and a point on it (metres):
        the drag's component around it turns the garment about it (`body_axis`).
    turn : (V,) float64 in [0, 1], how much of that turn each vertex takes (0 on another limb: `turn_weights`).
    """

    vertex: int
    weight: np.ndarray
    distance_grab_m: np.ndarray
    distance_pin_m: np.ndarray
    parent: np.ndarray
    held: np.ndarray
    axis: np.ndarray
    axis_point: np.ndarray
    turn: np.ndarray


@dataclass
class MoveStats:
    """What one `move_to` / `move_by` did.

    updates : drag updates run (the move split at `max_step_m`). grab_moved_m : how far the grab's foot went
    along its path, metres. max_vertex_move_m : the largest move of any vertex, metres. seconds : wall time.
    update_seconds : wall time of each update (propagation + relaxation), seconds.
    """

    updates: int = 0
    grab_moved_m: float = 0.0
    max_vertex_move_m: float = 0.0
    seconds: float = 0.0
    update_seconds: list[float] = field(default_factory=list)


@dataclass
class ReleaseStats:
    """What one `release` did.

    seconds : wall time. polished : whether the release's polish was kept (it runs where the max strain is above
    `release_polish_above`). new_vertices : vertices its refinement added (the session goes on with them).
    grab_gave_m : how far the let-go point moved from where it was let go, metres (0 unless `release_give_m`
    had to be used). strain_max : the max edge strain after it (fraction).
    """

    seconds: float = 0.0
    polished: bool = False
    new_vertices: int = 0
    grab_gave_m: float = 0.0
    strain_max: float = 0.0

    def to_dict(self) -> dict[str, float | int | bool]:
        return {
            "release_s": round(self.seconds, 4),
            "polished": self.polished,
            "new_vertices": self.new_vertices,
            "grab_gave_m": round(self.grab_gave_m, 5),
            "strain_max": round(self.strain_max, 5),
        }


@dataclass
class _Snapshot:
    state: ClothState
    feet: ClothState
    pinned: np.ndarray
    grabbed: Grab | None
    solver: GlobalRelax | None
    model: ClothModel
    file: GarmentFile
    refinement: tuple[np.ndarray | None, np.ndarray | None]


class DragSession:
    """A dressed garment on a body, ready to be dragged along it (see the module docstring).

    body : a `kitsuke.body.Body` or a closed TriMesh (metres).
    garment : a DressedGarment (from `wrap`) or a GarmentFile (`read_garment_obj`: its vt are the rest shape).
    params : DragParams. collider : a prepared BodyCollider of `body` (built if None).
    source : the file the garment or the drags come from, named in errors.

    Attributes: `positions` (V, 3) float64 metres, the garment now; `pinned` (V,) bool; `grabbed` (the Grab, or
    None); `model` (ClothModel: rest shape from the pattern); `body_mesh` (TriMesh); `collider`.
    """

    def __init__(
        self,
        body,
        garment: DressedGarment | GarmentFile,
        *,
        params: DragParams | None = None,
        collider: BodyCollider | None = None,
        source: str | None = None,
    ) -> None:
        self.params = params or DragParams()
        if not isinstance(self.params, DragParams):
            raise InputError("params must be a DragParams")
        self.source = source
        if not isinstance(garment, DressedGarment | GarmentFile):
            raise InputError("garment must be a DressedGarment or a GarmentFile (read_garment_obj)")
        self._file = as_garment_file(garment)
        mesh = body if isinstance(body, TriMesh) else body.mesh
        self.body_mesh: TriMesh = mesh
        if collider is None:
            collider = BodyCollider.from_mesh(mesh) if isinstance(body, TriMesh) else BodyCollider.from_body(body)
        if not isinstance(collider, BodyCollider):
            raise InputError("collider must be a BodyCollider")
        self.collider = collider
        names = [] if isinstance(body, TriMesh) else [c.name for c in body.capsules]
        self._capsule_limb = capsule_limbs(names, len(collider.capsule_ends))
        f = self._file
        cloth = offset_as_dressed(garment, self.params.cloth)
        self._file = dataclasses.replace(self._file, contact_offset_m=cloth.contact_offset_m)  # what it is dragged at
        try:
            self.model = ClothModel.from_corners(
                f.faces, f.rest_shape, n_vertices=len(f.positions), params=cloth, face_layer=f.face_layer
            )
            self.state = ClothState.new(self.model, f.positions)
        except InputError as e:
            raise InputError(e.message, source or e.path) from None
        nv = self.model.n_vertices
        self.pinned = np.zeros(nv, dtype=bool)
        self.grabbed: Grab | None = None
        self._solver: GlobalRelax | None = None
        self._moved = False
        self._surface = collider.surface_for(mesh)
        self._refinement: tuple[np.ndarray | None, np.ndarray | None] = (None, None)  # polish_refined's level, pending
        self._new_feet()

    # -- state ----------------------------------------------------------------------------------------------
    @property
    def positions(self) -> np.ndarray:
        """(V, 3) float64, metres: the garment now (the live array; copy it to keep it)."""
        return self.state.positions

    @property
    def n_vertices(self) -> int:
        return self.model.n_vertices

    def garment(self) -> GarmentFile:
        """The garment now (positions copied), for `write_garment_obj` / `write_garment_png`."""
        f = self._file
        return dataclasses.replace(f, positions=self.state.positions.copy())

    def report(self) -> QualityReport:
        """The SPEC §6 quality report of the garment now against the body."""
        m = self.model
        return quality_report(
            self.state.positions,
            m.faces,
            self.body_mesh,
            rest_lengths=m.rest_lengths,
            rest_areas=m.rest_areas,
            pieces=(self._file.piece_names, self._file.piece_faces),
        )

    def snapshot(self) -> _Snapshot:
        """Everything a drag changes, for `restore` (a drags file found bad half-way leaves the garment as it was)."""
        return _Snapshot(
            self.state.copy(),
            self._feet.copy(),
            self.pinned.copy(),
            self.grabbed,
            self._solver,
            self.model,
            self._file,
            self._refinement,
        )

    def restore(self, snap: _Snapshot) -> None:
        """Put the session back as it was at `snap` (the positions array keeps its identity unless a release has
        refined the garment since)."""
        if snap.model is not self.model:
            self.model, self._file, self._refinement = snap.model, snap.file, snap.refinement
            self.state = snap.state.copy()
            self._new_feet()
        else:
            self.state.positions[:] = snap.state.positions
            self.state.contacts = snap.state.copy().contacts
        self._feet.contacts = snap.feet.copy().contacts
        self.pinned = snap.pinned.copy()
        self.grabbed, self._solver = snap.grabbed, snap.solver

    def _new_feet(self) -> None:
        """The per-vertex helpers of a (new) model: each vertex's foot on the body, tracked by walking from where
        it was (never a global jump to another body part while the walk succeeds: the state's own contacts stop
        tracking cloth far from the body), and the drag's work arrays."""
        nv = self.model.n_vertices
        self._foot_model = self.model.with_params(dataclasses.replace(self.params.cloth, track_distance_m=1e3))
        self._feet = ClothState.new(self._foot_model, self.state.positions)
        self._track_feet()
        self._vec = np.zeros((nv, 3))
        self._move = np.zeros((nv, 3))

    def _adopt(self, refined: RefinedPolish) -> None:
        """Go on with the garment a release's polish refined: faces back in piece order, pins kept (old vertices
        keep their indices), new vertices free."""
        ordered = pieces_contiguous(refined, self._file.piece_faces)
        state = reorder_state(refined.state, ordered)
        self._file = dataclasses.replace(
            self._file,
            positions=state.positions,
            faces=ordered.model.faces,
            corner_uv=ordered.corner_uv,
            piece_faces=ordered.piece_faces,
            face_layer=ordered.model.face_layer,
            rest_corners=None if self._file.rest_corners is None else ordered.model.rest_corners,
        )
        # The session's own state holds no pins: each step is given the ones it holds.
        self.model, self.state = ordered.model, state.holding(np.zeros(ordered.model.n_vertices, dtype=bool))
        self._refinement = (ordered.level, ordered.pending)
        self.pinned = np.concatenate([self.pinned, np.zeros(self.model.n_vertices - len(self.pinned), dtype=bool)])
        self._new_feet()

    # -- picking and pins -----------------------------------------------------------------------------------
    def _points(self, points, what: str) -> np.ndarray:
        p = np.asarray(points, dtype=np.float64)
        if p.ndim == 1:
            p = p.reshape(1, -1)
        if p.ndim != 2 or p.shape[1] != 3:
            raise InputError(f"{what} must be 3D points (n, 3), got shape {p.shape}", self.source)
        if not np.isfinite(p).all():
            raise InputError(f"{what} holds NaN or infinity", self.source)
        return p

    def vertices_at(self, points, *, what: str = "point") -> np.ndarray:
        """The garment vertex nearest each of `points` (n, 3) metres: (n,) int64. Raises InputError for a point
        farther than `max_pick_distance_m` from every garment vertex (off the garment)."""
        from scipy.spatial import cKDTree

        p = self._points(points, what)
        dist, idx = cKDTree(self.state.positions).query(p)
        far = dist > self.params.max_pick_distance_m
        if far.any():
            i = int(np.argmax(far))
            raise InputError(
                f"{what} {np.round(p[i], 4).tolist()} is off the garment: {dist[i] * 100:.1f} cm from its nearest "
                f"vertex (at most {self.params.max_pick_distance_m * 100:.1f} cm)",
                self.source,
            )
        return idx.astype(np.int64)

    def _vertices(self, vertices) -> np.ndarray:
        v = np.atleast_1d(np.asarray(vertices))
        if v.ndim != 1 or not np.issubdtype(v.dtype, np.integer):
            raise InputError("vertices must be integer vertex indices", self.source)
        if len(v) and (v.min() < 0 or v.max() >= self.n_vertices):
            raise InputError(f"vertex index out of range 0..{self.n_vertices - 1}", self.source)
        return v.astype(np.int64)

    def pin(self, points=None, *, vertices=None) -> np.ndarray:
        """Pin the garment vertices nearest `points` (n, 3) metres, or `vertices` (indices): they stay exactly where
        they are and stop the drag's propagation. Returns the pinned vertex indices (n,) int64."""
        self._no_grab("pin")
        idx = self.vertices_at(points, what="pin") if vertices is None else self._vertices(vertices)
        self.pinned[idx] = True
        return idx

    def unpin(self, points=None, *, vertices=None, all: bool = False) -> np.ndarray:  # noqa: A002 (reads well)
        """Unpin the vertices nearest `points`, or `vertices`, or every pin (`all=True`). Returns those unpinned."""
        self._no_grab("unpin")
        if all:
            idx = np.flatnonzero(self.pinned)
        else:
            idx = self.vertices_at(points, what="unpin point") if vertices is None else self._vertices(vertices)
        self.pinned[idx] = False
        return idx

    def _no_grab(self, what: str) -> None:
        if self.grabbed is not None:
            raise InputError(f"cannot {what} while the garment is grabbed: release it first", self.source)

    # -- grab and release -----------------------------------------------------------------------------------
    def grab(self, point=None, *, vertex: int | None = None) -> Grab:
        """Grab the garment at the vertex nearest `point` (3,) metres (or at `vertex`): the dependency graph, the
        weights, the body part's axis and the factorised global relaxation. Raises InputError for a point off the
        garment, a pinned vertex, or a garment whose every vertex is pinned."""
        self._no_grab("grab")
        if self.pinned.all():
            raise InputError("every garment vertex is pinned: nothing can be dragged", self.source)
        if vertex is None:
            if point is None:
                raise InputError("grab needs a point or a vertex", self.source)
            g = int(self.vertices_at(point, what="grab point")[0])
        else:
            g = int(self._vertices(vertex)[0])
        if self.pinned[g]:
            raise InputError(f"the grabbed vertex {g} is pinned: unpin it first", self.source)
        m = self.model
        weight, d_grab, d_pin, parent = drag_weights(m, g, self.pinned, falloff=self.params.falloff)
        held = self.pinned | ~np.isfinite(d_grab)
        feet = self._feet.contacts
        axis, axis_point = body_axis(self.collider, feet.point[g])
        if len(self._capsule_limb):
            limb = self._capsule_limb[nearest_capsule(self.collider, feet.point)]
            turn = turn_weights(m, limb, np.abs(feet.distance) < self.params.far_m, g, self.params.turn_blend_m)
        else:
            turn = np.ones(m.n_vertices)
        self.grabbed = Grab(g, weight, d_grab, d_pin, parent, held, axis, axis_point, turn)
        # The held vertices do not change while the grab lasts: factorise the global relaxation now (mouse down),
        # not in the first update.
        held_grab = held.copy()
        held_grab[g] = True
        self._solver = self._global_solver(held_grab) if self.params.global_steps else None
        self._moved = False
        return self.grabbed

    def release(self) -> ReleaseStats:
        """Let go (mouse up): up to `release_steps` global relaxation steps, `release_relax_iterations` local ones
        and `release_untangle_rounds` of untangling, the let-go point and the cloth the grab did not reach held;
        then, where the max strain is above `release_polish_above`, the polish (which may refine; the let-go point
        may give by `release_give_m` if held it cannot meet the target). Nothing happens if the grab never moved."""
        t0 = time.perf_counter()
        if self.grabbed is None:
            return ReleaseStats()
        if not self._moved:  # grabbed and let go: nothing to relax
            self.grabbed, self._solver = None, None
            return ReleaseStats()
        g = self.grabbed.vertex
        held = self.grabbed.held.copy()
        # The let-go point stays where the user left it: released, shape matching (which has no friction without
        # gravity) would let compressed cloth spring back, unrolling a rolled-up sleeve.
        held[g] = True
        self.grabbed, self._solver = None, None
        p = self.params
        holding = self.state.holding(held)
        if p.release_steps:
            solver = self._global_solver(held)
            until_still(lambda: solver.step(holding, self.collider), p.release_steps, p.release_tolerance_m)
        if p.release_relax_iterations:
            relax(self.model, holding, self.collider, iterations=p.release_relax_iterations)
        untangling = Untangling(p.release_untangle_rounds, iterations=p.release_untangle_iterations)
        untangle_stage(self.model, holding, self.collider, untangling)
        m = self.model
        stats = ReleaseStats(strain_max=strain(self.state.positions, m.edges, m.rest_lengths).max)
        let_go = self.state.positions[g].copy()
        polish = p.release_polish_rounds and stats.strain_max > p.release_polish_above
        polished = self._release_polish(g, held) if polish else None
        if polished is not None and polished.levels:
            self._adopt(polished)  # new feet, tracked
        else:
            if polished is not None:
                self.state.positions[:] = polished.state.positions
                self.state.contacts = polished.state.contacts
            self._track_feet()
        if polished is not None:
            stats.polished = True
            stats.new_vertices = self.n_vertices - m.n_vertices
            stats.grab_gave_m = float(np.linalg.norm(self.state.positions[g] - let_go))
            stats.strain_max = strain(self.state.positions, self.model.edges, self.model.rest_lengths).max
        stats.seconds = time.perf_counter() - t0
        return stats

    def _release_polish(self, g: int, held: np.ndarray) -> RefinedPolish | None:
        """The release's polish (`_polish_step`) of the cloth, `held` (V,) bool still (`g` the let-go point among it):
        with g held; if that leaves the max strain above `release_polish_above`, with g tethered within each of
        `release_give_m` in turn; if none of those is kept, once more held without refinement (refining cloth
        crushed into an armpit can tear it: GarmentCode's shirt, its front hem lifted 5 cm against a pin in the
        back, 50.8 % max strain; every refined polish tore it, the unrefined one left 34 %; with the body moved by
        1 nm the refined one was kept, 6-9 %: the fallback is for the unlucky case). Returns the first
        result that meets the target, else the kept one with the lowest max strain, else None (nothing kept)."""
        p = self.params
        settings = PolishSettings(
            rounds=p.release_polish_rounds,
            iterations=p.release_polish_iterations,
            levels=p.release_polish_levels,
            max_folds=p.release_polish_max_folds,
            untangle_rounds=p.release_untangle_rounds,
            untangle_iterations=p.release_untangle_iterations,
        )
        best, best_max = None, math.inf
        for give in (0.0, *p.release_give_m):
            polished = self._polish_try(g, held, settings, give)
            if polished is None:
                continue
            worst = strain(polished.state.positions, polished.model.edges, polished.model.rest_lengths).max
            if worst < best_max:
                best, best_max = polished, worst
            if worst <= p.release_polish_above:
                break
        if best is None and p.release_polish_levels:
            best = self._polish_try(g, held, dataclasses.replace(settings, levels=0), 0.0)
        return best

    def _polish_try(self, g: int, held: np.ndarray, settings: PolishSettings, give: float) -> RefinedPolish | None:
        """One polish of the cloth, `held` (V,) bool still, g held (give 0) or tethered within `give` metres: the
        RefinedPolish if `polish_step` keeps it, else None. The session's state is left as it was."""
        m = self.model
        pins = held.copy()
        tethers = None
        if give:
            face = int(np.flatnonzero((m.faces == g).any(axis=1))[0])
            bary = (m.faces[face] == g).astype(np.float64)[None]
            tethers = Tethers.from_polylines(
                [(np.array([face]), bary, self.state.positions[g][None].copy())], m.faces, give
            )
            pins[g] = False
        level, pending = self._refinement
        kept, polished = polish_step(
            m,
            self.state.holding(pins),
            self.collider,
            settings,
            tethers=tethers,
            corner_data={"uv": m.rest_corners},
            level=level,
            pending=pending,
        )
        return polished if kept else None

    def _global_solver(self, held: np.ndarray) -> GlobalRelax:
        """A global relaxation of the session's cloth with `held` pinned, each vertex's move per step cut to
        `max_relax_move_m`."""
        p = self.params
        # Planes only under the cloth that touches the body (collision leaves it at the offset).
        reach = self.model.params.contact_offset_m + CONTACT_ROUNDOFF_M
        return GlobalRelax(
            self.model,
            held,
            contact_weight=p.contact_weight,
            contact_reach_m=reach,
            cg_iterations=p.contact_iterations,
            max_move_m=p.max_relax_move_m,
        )

    # -- moves ----------------------------------------------------------------------------------------------
    def _grab_or_raise(self) -> Grab:
        if self.grabbed is None:
            raise InputError("nothing is grabbed: grab the garment first", self.source)
        return self.grabbed

    def _track_feet(self) -> None:
        self._feet.positions = self.state.positions
        track(self._foot_model, self._feet, self.collider)

    def project(self, point, *, what: str = "target") -> tuple[int, np.ndarray, np.ndarray]:
        """The body point nearest `point` (3,) metres: (face, barycentrics (3,), point (3,)). Raises InputError for
        a point farther than `max_target_distance_m` from the body (off the body)."""
        p = self._points(point, what)
        sp = self._surface.closest(p)
        if sp.distance[0] > self.params.max_target_distance_m:
            raise InputError(
                f"{what} {np.round(p[0], 4).tolist()} is off the body: {sp.distance[0] * 100:.1f} cm from its "
                f"surface (at most {self.params.max_target_distance_m * 100:.1f} cm)",
                self.source,
            )
        return int(sp.faces[0]), sp.barycentric[0], sp.points[0]

    def move_to(self, point) -> MoveStats:
        """Drag the grab's foot to the body point nearest `point` (3,) metres; the grab keeps its height above the
        body. The move is split into updates of at most `max_step_m`, each target on the body."""
        grab = self._grab_or_raise()
        target = self.project(point)
        t0 = time.perf_counter()
        c = self._feet.contacts
        start = c.point[grab.vertex].copy()
        chord = target[2] - start
        n = max(1, math.ceil(float(np.linalg.norm(chord)) / self.params.max_step_m))
        stats = MoveStats(updates=n)
        before = self.state.positions.copy()
        for k in range(1, n + 1):
            q = target if k == n else self.project(start + chord * (k / n), what="path point")
            foot = c.point[grab.vertex].copy()
            t = time.perf_counter()
            self.update(q[2] - foot, target=q)
            stats.update_seconds.append(time.perf_counter() - t)
            stats.grab_moved_m += float(np.linalg.norm(c.point[grab.vertex] - foot))
        stats.max_vertex_move_m = float(np.linalg.norm(self.state.positions - before, axis=1).max())
        stats.seconds = time.perf_counter() - t0
        return stats

    def move_by(self, vector) -> MoveStats:
        """Drag the grab by `vector` (3,) metres: its part along the body's tangent plane at the grab, followed
        along the body surface (a geodesic), gives the target of `move_to`."""
        grab = self._grab_or_raise()
        v = self._points(vector, "vector")
        c = self._feet.contacts
        g = grab.vertex
        col = self.collider
        out_f, out_b, out_p, out_d = np.zeros(1, np.int64), np.zeros((1, 3)), np.zeros((1, 3)), np.zeros(1)
        K.trace_points(
            col.vertices, col.faces, col.face_adjacency, col.face_normals, c.face[g : g + 1], c.bary[g : g + 1],
            v, self.params.max_crossings, out_f, out_b, out_p, out_d,
        )  # fmt: skip
        return self.move_to(out_p[0])

    def update(self, displacement, *, target: tuple[int, np.ndarray, np.ndarray] | None = None) -> None:
        """One drag update (module docstring, steps 3 and 4): `displacement` (3,) metres of the grab's foot, laid
        into the body's tangent plane there (keeping its length), spread over the garment; then relaxation.
        `target` (face, barycentrics, point), if given, is where the grab's foot ends up exactly."""
        grab = self._grab_or_raise()
        p = self.params
        col, m = self.collider, self.model
        c = self._feet.contacts
        g = grab.vertex
        d = np.asarray(displacement, dtype=np.float64).reshape(3)
        if not np.isfinite(d).all():
            raise InputError("displacement holds NaN or infinity", self.source)
        n = c.normal[g]
        tangent = d - (d @ n) * n
        length = float(np.linalg.norm(d))
        t_len = float(np.linalg.norm(tangent))
        if t_len > 0:
            tangent *= length / t_len
        pos = self.state.positions
        # The drag as a rigid motion of the body part: a turn about its axis for the component around it (the
        # angle that moves the grab's foot by that much), a translation for the rest.
        ax, centre = grab.axis, grab.axis_point
        r = c.point[g] - centre
        r -= (r @ ax) * ax
        radius = float(np.linalg.norm(r))
        around = np.cross(ax, r) / radius if radius > 1e-6 else np.zeros(3)
        d_around = float(tangent @ around)
        omega = d_around / radius if radius > 1e-6 else 0.0
        # How much each vertex keeps to the body: 1 near it, 0 far from it, smooth between.
        follow = 1.0 - smooth_falloff((np.abs(c.distance) - p.near_m) / (p.far_m - p.near_m))
        # The turn: cloth that keeps to the body slides round it, along the surface's own direction round the
        # axis (axis x normal), at the grab's speed, as a belt runs round its pulleys; a rigid turn would drive the
        # kimono's hem into the ankles it wraps (a narrow tube round two legs is not a circle about the torso's
        # axis). Cloth away from the body, and where the surface faces along the axis, turns rigidly.
        spin = np.cross(ax, pos - centre)
        belt = np.cross(ax, c.normal)
        belt_len = np.linalg.norm(belt, axis=1)
        side = np.sign(np.einsum("ij,ij->i", belt, spin)) / np.maximum(belt_len, 1e-12)
        mix = (follow * smooth_falloff(belt_len / BELT_MIN_SIN))[:, None]
        spin = (1.0 - mix) * spin + mix * (radius * side)[:, None] * belt
        self._vec[:] = (omega * grab.turn)[:, None] * spin + (tangent - d_around * around)
        follow[g] = 1.0
        self._vec[g] = tangent
        K.drag_moves(
            pos, grab.weight, follow, self._vec, col.vertices, col.faces, col.face_adjacency, col.face_normals,
            col.vertex_normals, p.max_crossings, c.face, c.bary, c.point, self._move,
        )  # fmt: skip
        if target is not None:  # the grab's foot ends exactly on its target, the grab at its height above it
            f, bary, point = target
            pos[g] += point - c.point[g]
            c.face[g], c.bary[g], c.point[g] = f, bary, point
        self._moved = True
        held = grab.held.copy()
        held[g] = True
        holding = self.state.holding(held)
        if self._solver is not None:
            if p.contact_weight > 0:  # the contact planes where the cloth is now, not where it was
                collide(m, holding, self.collider)
            for _ in range(p.global_steps):
                self._solver.step(holding, self.collider)
        if p.relax_iterations:
            relax(m, holding, self.collider, iterations=p.relax_iterations)
        self._track_feet()
