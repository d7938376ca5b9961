"""The kimono simulated on a body moved by poses (SPEC §5.1, §5.4): poses → (corrected) → the default body
posed → the dressed kimono stepped once a frame, its waist held in the obi.

from kitsuke.pose import load_poses
from kitsuke.tryon import simulate_kimono
motion = simulate_kimono(load_poses("walk.bvh"))      # dresses the default kimono, corrects the legs
motion.quality[-1].strain_max, motion.positions.shape  # per-frame measures; (n, V, 3) cloth vertices

`KimonoSimulator` is the same loop one frame at a time (what a live mirror calls per camera frame).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ..body.animate import BodyAnimation, animate
from ..body.capsules import capsule_segments
from ..body.skinning import skin
from ..cloth import BodyCollider, ClothModel, ClothParams, ClothState, DynamicsParams, dynamics_data, step
from ..cloth._dynamics import MovingBody
from ..errors import ComputationError, InputError
from ..metrics import QualityTargets, penetration, strain
from ..skeleton import INDEX, JOINTS
from .motion import check_lead_in, with_lead_in

#: Target edge length (cm) of the kimono dressed for simulation: about 5,100 vertices on the default kimono
#: (the demo's 1.5 cm gives 16,000: three times the cost a step, and slower to converge).
SIMULATION_EDGE_CM = 2.5


#: Half the cloth farther than this from the skin (metres) means the simulation lost the kimono: exit 1, nothing
#: written. Dressed, half of it lies within 4 cm of the skin (sleeves hang off it).
OFF_BODY_M = 0.15


@dataclass(frozen=True)
class SimulationSettings:
    """How `simulate_kimono` runs.

    correct : correct the legs for a kimono first (`kitsuke.pose.correct_poses`), as the try-on does: a kimono
        cannot follow legs that stride wider than its hem, and simulated on them it tears or is pierced.
    hold_s, blend_s : the lead-in from the rest pose the kimono was dressed in (`kitsuke.tryon.motion`), seconds.
    dynamics : the cloth solver's settings.
    targets : what each frame is measured against: vertices more than `penetration_mm` inside the body, the
        largest edge strain against the pattern (`QualityTargets.motion()`).
    """

    correct: bool = True
    hold_s: float = 0.2
    blend_s: float = 0.5
    dynamics: DynamicsParams = field(default_factory=DynamicsParams)
    targets: QualityTargets = field(default_factory=lambda: QualityTargets.motion())

    def __post_init__(self) -> None:
        check_lead_in(self.hold_s, self.blend_s)  # before any work: a bad setting should not cost a dressing


@dataclass(frozen=True)
class FrameQuality:
    """One simulated frame. time_s : its time in the clip (negative in the lead-in). lead_in : part of the lead-in.
    penetration_count : cloth vertices deeper inside the body than the target (winding-number test).
    penetration_deepest_mm : the deepest one. strain_max, strain_mean : edge strain against the pattern's lengths
    (fractions). step_s : wall time of the simulation step, seconds (measuring not included). ok : within targets.
    """

    time_s: float
    lead_in: bool
    penetration_count: int
    penetration_deepest_mm: float
    strain_max: float
    strain_mean: float
    step_s: float
    ok: bool

    def to_dict(self) -> dict:
        return {
            "time_s": round(self.time_s, 4),
            "lead_in": self.lead_in,
            "penetration_count": self.penetration_count,
            "penetration_deepest_mm": round(self.penetration_deepest_mm, 2),
            "strain_max": round(self.strain_max, 5),
            "strain_mean": round(self.strain_mean, 6),
            "step_s": round(self.step_s, 5),
            "ok": self.ok,
        }


def cloth_model(garment) -> ClothModel:  # noqa: ANN001 - DressedGarment or GarmentFile
    """The cloth model of a dressed garment (its pattern's rest shape, layers and offset off the body)."""
    from ..dressing.export import as_garment_file

    g = as_garment_file(garment)
    offset = g.contact_offset_m if g.contact_offset_m else ClothParams().contact_offset_m
    return ClothModel.from_corners(
        g.faces,
        g.rest_shape,
        n_vertices=len(g.positions),
        face_layer=g.face_layer,
        params=ClothParams(contact_offset_m=offset),
    )


def _trunk_faces(body) -> np.ndarray:  # noqa: ANN001
    """(F,) bool, the body's faces moved almost only by the pelvis, spine and chest (the obi holds to them, not to
    an arm hanging beside the waist)."""
    w = body.rig.weights[:, [INDEX["pelvis"], INDEX["spine"], INDEX["chest"]]].sum(axis=1) > 0.8
    return w[body.mesh.faces].all(axis=1)


class KimonoSimulator:
    """A dressed kimono on a rigged body, advanced one frame at a time.

    body : a rigged `kitsuke.body.Body` in its rest pose (the kimono was dressed on it).
    garment : the dressed kimono (`DressedGarment` or a `GarmentFile` read from its OBJ).
    weights : (V, J) the skin weights to pose with (`BodyAnimation.weights`).
    """

    def __init__(self, body, garment, weights: np.ndarray, settings: SimulationSettings | None = None) -> None:  # noqa: ANN001
        from ..dressing.export import as_garment_file
        from ..dressing.kimono import obi_band

        if body.rig is None:
            raise InputError("simulating a kimono needs a rigged body (the default body)", body.source or None)
        self.settings = settings or SimulationSettings()
        self.body = body
        self.weights = weights
        g = as_garment_file(garment)
        self.model = cloth_model(g)
        self.state = ClothState.new(self.model, g.positions)
        self.data = dynamics_data(self.model, self.settings.dynamics, start=g.positions)
        self.moving = MovingBody.of(BodyCollider.from_body(body))
        low, high = obi_band(body)
        held = self.moving.hold_band(g.positions, low, high, on_faces=_trunk_faces(body))
        if len(held.vertices) == 0:
            raise InputError(f"the garment {g.name!r} has no cloth at the obi's height on this body: not a kimono?")
        self.frames = 0

    def advance(self, rotations: np.ndarray, joints: np.ndarray, dt: float) -> np.ndarray:
        """Move the body to the pose (J, 3, 3) world rotations, (J, 3) joints (metres) and step the cloth `dt`
        seconds; returns the skin's vertices (Vb, 3). ComputationError ("simulation") names the frame when the
        cloth diverges or leaves the body (`OFF_BODY_M`)."""
        rig = self.body.rig
        skin_v = skin(self.body.mesh.vertices, self.weights, rig.joints, rotations, joints)
        ends, _ = capsule_segments(self.body.capsules, joints, rotations)
        self.moving.move_to(ends, skin_v)
        try:
            step(self.model, self.state, self.moving, dt, self.settings.dynamics, self.data)
        except ComputationError as e:
            raise ComputationError("simulation", f"frame {self.frames}: {e.message}") from None
        # a kimono whose cloth mostly left the body is no kimono on it (its sleeves hang up to ~25 cm off)
        off = float(np.median(self.state.contacts.distance))
        if off > OFF_BODY_M:
            raise ComputationError(
                "simulation", f"frame {self.frames}: the kimono left the body (half its cloth {off:.2f} m off it)"
            )
        self.frames += 1
        return skin_v

    def measure(self, skin_v: np.ndarray) -> tuple[int, float, float, float]:
        """(penetration count, deepest mm, max strain, mean strain) of the cloth now on the skin (Vb, 3)."""
        from ..geometry import TriMesh

        t = self.settings.targets
        pen = penetration(
            self.state.positions, TriMesh(skin_v, self.body.mesh.faces), threshold_m=t.penetration_mm / 1e3
        )
        s = strain(self.state.positions, self.model.edges, self.model.rest_lengths)
        return pen.count, pen.deepest_mm, s.max, s.mean


@dataclass
class KimonoMotion:
    """A simulated kimono over a body animation.

    animation : the body's animation, lead-in included (`n_lead` frames first). positions : (n, V, 3) float32 cloth
    vertices per frame, metres. quality : per frame. garment : the dressed kimono it started from (its faces,
    uvs, pieces). corrected : whether the legs were corrected. seconds : wall time of the whole simulation.
    """

    animation: BodyAnimation
    n_lead: int
    positions: np.ndarray
    quality: list[FrameQuality]
    garment: object
    corrected: bool
    seconds: float

    def summary(self) -> dict:
        """JSON-ready: frame counts, worst and median measures over the clip (the lead-in apart), and per frame."""
        clip = [q for q in self.quality if not q.lead_in] or self.quality
        steps = np.array([q.step_s for q in self.quality])
        return {
            "frames": len(self.quality),
            "lead_in_frames": self.n_lead,
            "fps": self.animation.fps,
            "corrected": self.corrected,
            "vertices": int(self.positions.shape[1]),
            "frames_within_targets": sum(q.ok for q in clip),
            "clip_frames": len(clip),
            "worst": {
                "penetration_count": max(q.penetration_count for q in clip),
                "penetration_deepest_mm": round(max(q.penetration_deepest_mm for q in clip), 2),
                "strain_max": round(max(q.strain_max for q in clip), 5),
            },
            "median_strain_max": round(float(np.median([q.strain_max for q in clip])), 5),
            "simulated_fps": round(len(steps) / max(float(steps.sum()), 1e-9), 2),
            "seconds": round(self.seconds, 3),
            "per_frame": [q.to_dict() for q in self.quality],
        }


def default_simulation_kimono(body=None, pattern=None, edge_cm: float = SIMULATION_EDGE_CM):  # noqa: ANN001, ANN201
    """A kimono dressed on `body` (default: the default body) for simulation: `pattern` (default
    `default_kimono()`) at `edge_cm` (default `SIMULATION_EDGE_CM`), without the polish's refinement of folds
    (its 3 mm edges, sqrt(3) levels down from 2.5 cm, are crushed and jitter in a moving simulation: on a walk,
    96 % of the edges strained over 10 % in its first frames were such edges)."""
    from ..dressing.kimono import dress_kimono
    from ..dressing.wrap import WrapParams
    from ..pattern import default_kimono

    params = WrapParams(edge_length_cm=edge_cm).changed({"polish.levels": 0})
    return dress_kimono(default_kimono() if pattern is None else pattern, body, params=params)


def simulate_kimono(
    poses,  # noqa: ANN001 - a kitsuke.pose.PoseSequence
    *,
    body=None,  # noqa: ANN001
    garment=None,  # noqa: ANN001
    constraints=None,  # noqa: ANN001
    settings: SimulationSettings | None = None,
    progress: bool | None = None,
) -> KimonoMotion:
    """Simulate a dressed kimono on `body` moved by `poses`.

    body : a rigged Body (default `default_body()`); garment : the kimono dressed on it in its rest pose (default
    `default_simulation_kimono()`); constraints : the E/A table for the leg correction (default the shipped one).
    InputError for poses without a valid frame, NaN in the poses, or a garment that no obi holds.
    ComputationError ("simulation") names the frame where the cloth diverged.
    """
    from .._progress import progress as bar
    from ..body import default_body

    s = settings or SimulationSettings()
    body = default_body() if body is None else body
    check_poses(poses)
    corrected = poses
    if s.correct:
        from ..pose import correct_poses

        corrected = correct_poses(poses, constraints).poses
    animation, n_lead = with_lead_in(animate(body, corrected), body.rig.joints, hold_s=s.hold_s, blend_s=s.blend_s)
    garment = default_simulation_kimono(body) if garment is None else garment
    sim = KimonoSimulator(body, garment, animation.weights, s)
    t_start = time.perf_counter()
    out = np.empty((animation.n_frames,) + sim.state.positions.shape, dtype=np.float32)
    quality: list[FrameQuality] = []
    dt = 1.0 / animation.fps
    t = s.targets
    frames = range(animation.n_frames)
    for f in bar(frames, total=animation.n_frames, desc="simulating", enabled=progress or None):
        t0 = time.perf_counter()
        skin_v = sim.advance(animation.rotations[f], animation.joints[f], dt)
        took = time.perf_counter() - t0
        count, deepest, smax, smean = sim.measure(skin_v)
        out[f] = sim.state.positions
        ok = count == 0 and smax <= t.max_strain
        time_s = float(animation.times[f] - animation.times[n_lead]) if n_lead < animation.n_frames else 0.0
        quality.append(FrameQuality(time_s, f < n_lead, count, deepest, smax, smean, took, ok))
    return KimonoMotion(animation, n_lead, out, quality, garment, s.correct, time.perf_counter() - t_start)


def check_poses(poses) -> None:  # noqa: ANN001
    pos = np.asarray(poses.positions, dtype=np.float64)
    where = poses.source.get("path") if isinstance(poses.source, dict) else None
    if pos.ndim != 3 or pos.shape[1:] != (len(JOINTS), 3):
        raise InputError(f"poses must give the {len(JOINTS)} joints of kitsuke's skeleton per frame", where)
    valid = np.asarray(poses.valid, dtype=bool)
    if not valid.any():
        raise InputError("the poses have no frame with a person in it", where)
    bad = ~np.isfinite(pos[valid]).all(axis=(1, 2))
    if bad.any():
        first = int(np.flatnonzero(valid)[np.flatnonzero(bad)[0]])
        raise InputError(f"frame {first} of the poses holds NaN or infinity", where)
