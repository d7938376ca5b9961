"""The try-on mirror, one camera frame at a time (SPEC §5.1): pose → filter → posture correction → the default
body posed → one kimono simulation step → the camera registered to the person → the kimono drawn over the frame.

from kitsuke.tryon import TryOn, open_frames
with TryOn() as mirror:                          # dresses the default kimono on the default body (a few seconds)
    for frame in open_frames("clip.mp4"):
        out = mirror.step(frame)                 # out.image: the frame with the kimono; out.residual_px, out.stage_s

Each stage is a small object with one job (`PoseStage`, `BodyStage`, `KimonoStage`, `Registrar`, `Compositor`);
`TryOn.step` only passes their results along. A frame without a pose keeps the kimono where it was and fades it out
over `fade_s`; when the person comes back after it has faded, the kimono is dressed again and blended onto them.
Two or more people: the largest in the image is dressed and followed while they stay (counted in
`MirrorFrame.people`); when they leave, whoever is largest is dressed afresh (`MirrorFrame.switched`).
"""

from __future__ import annotations

import time
from collections import deque
from dataclasses import dataclass, field

import numpy as np

from ..cloth import DynamicsParams
from ..errors import ComputationError
from ..pose import OneEuroConfig, OneEuroFilter, OnlineCorrector
from ..skeleton import INDEX
from .frames import Frame
from .register import Registration, fit_focal, focal_px, register
from .simulate import SIMULATION_EDGE_CM, KimonoSimulator, SimulationSettings, default_simulation_kimono

#: Edge length (cm) of the kimono for the live window: about 2,100 vertices, a simulation step about half the
#: cost of the file default (`SIMULATION_EDGE_CM`, about 5,100 vertices).
LIVE_EDGE_CM = 4.0
_FEET = [INDEX[j] for j in ("l_ankle", "l_heel", "l_toe", "r_ankle", "r_heel", "r_toe")]


@dataclass(frozen=True)
class TryOnSettings:
    """How the mirror runs.

    correct : hold the legs as a kimono would (the paper's posture correction); False drives the kimono with the
        raw pose (the legs poke through).
    edge_cm : the simulated kimono's edge length, cm (smaller: finer folds, slower).
    fade_s : a frame without a person keeps the kimono and fades it out over this many seconds.
    blend_s : when a person appears, the kimono (dressed on the rest pose) is blended onto their pose over this
        many seconds of simulation, before the frame is shown.
    focal_frames : frames with a pose over which the camera's focal length is fitted (a 60° field of view before).
    recover : a simulation that fails (diverges, leaves the body) is dressed afresh on the next frame and counted
        (`MirrorFrame.restarted`), instead of raising ComputationError: what a live mirror wants; a file's run
        stops and writes nothing.
    filter : the One-Euro filter of the joints.
    dynamics : the cloth solver's settings.
    """

    correct: bool = True
    edge_cm: float = SIMULATION_EDGE_CM
    fade_s: float = 1.0
    blend_s: float = 0.5
    focal_frames: int = 15
    recover: bool = False
    filter: OneEuroConfig = field(default_factory=OneEuroConfig)
    dynamics: DynamicsParams = field(default_factory=DynamicsParams)


@dataclass
class MirrorFrame:
    """One frame out of the mirror.

    index, time_s : the source frame. image : (H, W, 3) uint8, the frame with the kimono over it (None when not
    rendered). raw_image : the same with the kimono driven by the uncorrected pose (`TryOn(compare=True)`).
    people : people detected (the largest is dressed). posed : a pose was found and the kimono stepped.
    corrected : the correction rotated a leg. alpha : the kimono's opacity (below 1 while it fades out).
    residual_px : mean registration residual (pixels), NaN when not registered; joint_residuals_px : (J,) per
    joint (NaN for joints not used), None when not registered. strain_max : largest edge strain
    of the kimono. stage_s : wall time per stage, seconds. restarted : the simulation failed this frame and the
    kimono is dressed afresh on the next (`TryOnSettings.recover`). switched : the person followed left and
    another was taken (dressed afresh). raw_joints, joints : (J, 3) the filtered and the
    corrected joints, metres (None without a pose).
    """

    index: int
    time_s: float
    image: np.ndarray | None = None
    raw_image: np.ndarray | None = None
    people: int = 0
    posed: bool = False
    corrected: bool = False
    alpha: float = 0.0
    residual_px: float = float("nan")
    residual_p95_px: float = float("nan")
    joint_residuals_px: np.ndarray | None = None
    strain_max: float = float("nan")
    stage_s: dict[str, float] = field(default_factory=dict)
    restarted: bool = False
    switched: bool = False
    raw_joints: np.ndarray | None = None
    joints: np.ndarray | None = None


#: The person followed from frame to frame is the one whose box overlaps their last box most; below this overlap
#: (intersection over union) they are gone, and the largest person present is dressed afresh.
SAME_PERSON_IOU = 0.2


def _box(image: np.ndarray) -> np.ndarray:
    """(4,) x0, y0, x1, y1 pixels around a person's well-seen landmarks (all of them if fewer than 3 are)."""
    seen = image[:, 2] > 0.3
    pts = image[seen if seen.sum() >= 3 else slice(None), :2]
    return np.r_[pts.min(axis=0), pts.max(axis=0)]


def _iou(a: np.ndarray, b: np.ndarray) -> float:
    w = max(0.0, min(a[2], b[2]) - max(a[0], b[0]))
    h = max(0.0, min(a[3], b[3]) - max(a[1], b[1]))
    inter = w * h
    union = np.prod(a[2:] - a[:2]) + np.prod(b[2:] - b[:2]) - inter
    return float(inter / union) if union > 0 else 0.0


@dataclass(frozen=True)
class Observation:
    """The pose stage's result for one frame: people found, (J, 3) filtered joints (metres, Y up) and (J, 3) image
    joints (u, v pixels, visibility) of the person followed, or None; seconds it took. switched : the person
    followed is gone and another is taken (the kimono is dressed afresh on them)."""

    people: int
    joints: np.ndarray | None
    image: np.ndarray | None
    seconds: float
    switched: bool = False


class PoseStage:
    """MediaPipe on a frame, one person followed (the largest at first, then whoever overlaps their last place
    most: `SAME_PERSON_IOU`), joints filtered. Use as a context manager."""

    def __init__(self, config: OneEuroConfig) -> None:
        from ..pose import PoseLandmarker

        self._landmarker = PoseLandmarker("video", num_poses=2)
        self._filter = OneEuroFilter(config)
        self._box: np.ndarray | None = None

    def __enter__(self) -> PoseStage:
        from ..pose._mediapipe import _quiet_native_stderr

        with _quiet_native_stderr():
            self._landmarker.__enter__()
        return self

    def __exit__(self, *exc: object) -> None:
        self._landmarker.__exit__(*exc)

    def __call__(self, frame: Frame) -> tuple[int, np.ndarray | None, np.ndarray | None, bool]:
        """(people found, (J, 3) filtered world joints metres Y up, (J, 3) image joints u, v px and visibility,
        whether the person followed changed)."""
        from ..pose import image_to_joints, world_to_joints

        people = self._landmarker.detect_all(frame.rgb, int(round(frame.time_s * 1000.0)))
        if not people:
            return 0, None, None, False
        boxes = [_box(image) for _, image in people]
        switched = False
        if self._box is not None:
            overlap = [_iou(self._box, b) for b in boxes]
            k = int(np.argmax(overlap))
            if overlap[k] < SAME_PERSON_IOU:  # the one followed left: the largest one present is dressed afresh
                k, switched = int(np.argmax([np.prod(b[2:] - b[:2]) for b in boxes])), True
                self._filter.reset()
        else:
            k = int(np.argmax([np.prod(b[2:] - b[:2]) for b in boxes]))
        self._box = boxes[k]
        world, image = people[k]
        return len(people), self._filter(world_to_joints(world), frame.time_s), image_to_joints(image), switched

    def reset(self) -> None:
        """Forget the person followed (they have gone)."""
        self._filter.reset()
        self._box = None


class BodyStage:
    """Joints → the rigged body's rotations and posed joints, feet on the floor.

    MediaPipe's joints are hip-centred: the body is lifted so that its feet stand on y = 0, by the 5th percentile
    of the lowest foot over the last `window` posed frames (one frame's lowest foot would lift the feet of a
    jump to the floor and sink a squat)."""

    def __init__(self, body, window: int = 300) -> None:  # noqa: ANN001 - a rigged Body
        self.rest = body.rig.joints
        self._floor = float(self.rest[_FEET, 1].min())
        self._lowest: deque[float] = deque(maxlen=window)

    def __call__(self, joints: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(J, 3, 3) world rotations and (J, 3) posed joints, metres; this frame's feet count toward the floor."""
        rot, posed = self._posed(joints)
        self._lowest.append(float(posed[_FEET, 1].min()))
        posed[:, 1] -= self._lift()
        return rot, posed

    def reset(self) -> None:
        """Forget the floor (another person)."""
        self._lowest.clear()

    def pose(self, joints: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The same for another pose of the same frame (the uncorrected one), on the same floor."""
        rot, posed = self._posed(joints)
        posed[:, 1] -= self._lift()
        return rot, posed

    def _posed(self, joints: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        from ..body.skinning import forward_kinematics, rotations_from_positions

        rot = rotations_from_positions(self.rest, joints)
        return rot, forward_kinematics(self.rest, rot, joints[INDEX["pelvis"]])

    def _lift(self) -> float:
        return float(np.percentile(self._lowest, 5)) - self._floor


class KimonoStage:
    """The dressed kimono simulated on the body: `start` blends it from the rest pose onto a first pose, `step`
    advances one frame. The dressed state is kept, so `restart` dresses it again at no cost."""

    def __init__(self, body, garment, weights: np.ndarray, settings: TryOnSettings) -> None:  # noqa: ANN001
        self._args = (body, garment, weights, SimulationSettings(correct=False, dynamics=settings.dynamics))
        self.blend_s = settings.blend_s
        self.sim: KimonoSimulator | None = None
        self.skin: np.ndarray | None = None

    @property
    def started(self) -> bool:
        return self.sim is not None

    def start(self, rotations: np.ndarray, joints: np.ndarray, dt: float) -> None:
        """A fresh dressed kimono, walked from the rest pose to this one over `blend_s` (eased, slerped)."""
        from ..body.skinning import forward_kinematics
        from .motion import _slerp_from_identity

        self.sim = KimonoSimulator(*self._args)
        rest = self.sim.body.rig.joints
        n = max(1, int(round(self.blend_s / dt)))
        for k in range(1, n + 1):
            t = k / n
            t = t * t * (3.0 - 2.0 * t)
            rot = _slerp_from_identity(rotations, t)
            root = (1.0 - t) * rest[INDEX["pelvis"]] + t * joints[INDEX["pelvis"]]
            self.skin = self.sim.advance(rot, forward_kinematics(rest, rot, root), dt)

    def step(self, rotations: np.ndarray, joints: np.ndarray, dt: float) -> None:
        assert self.sim is not None
        self.skin = self.sim.advance(rotations, joints, dt)

    def stop(self) -> None:
        self.sim = None

    @property
    def positions(self) -> np.ndarray:
        assert self.sim is not None
        return self.sim.state.positions

    def strain_max(self) -> float:
        from ..metrics import strain

        assert self.sim is not None
        return float(strain(self.sim.state.positions, self.sim.model.edges, self.sim.model.rest_lengths).max)


class Registrar:
    """The camera per frame: focal length fitted over the first `focal_frames` posed frames, then fixed."""

    def __init__(self, size: tuple[int, int], focal_frames: int) -> None:
        self.size = size
        self.focal = focal_px(size, 60.0)
        self.fitted = focal_frames <= 0
        self._wanted = focal_frames
        self._seen: list[tuple[np.ndarray, np.ndarray]] = []
        self.last: Registration | None = None

    def __call__(self, joints: np.ndarray, image: np.ndarray) -> Registration | None:
        if not self.fitted:
            self._seen.append((joints, image))
            if len(self._seen) >= self._wanted:
                self.focal = fit_focal(self._seen, self.size)
                self.fitted = True
                self._seen.clear()
                self.last = None  # the pose fitted with the old focal length is no start for the new one
        reg = register(joints, image, self.focal, self.size, self.last)
        if reg is not None:
            self.last = reg
        return reg


class Compositor:
    """The kimono rendered with the registered camera and blended over the frame: textured and shaded, its
    edges anti-aliased (MSAA coverage as alpha), the posed body drawn into depth only so that the kimono's
    inside and back are hidden and the person's own head, hands and feet show through."""

    def __init__(self, body, garment) -> None:  # noqa: ANN001
        from ..render import Renderer
        from .outputs import kimono_template

        self.renderer = Renderer()
        self.faces = body.mesh.faces
        self.kimono, self.index = kimono_template(garment)

    def close(self) -> None:
        self.renderer.close()

    def __call__(
        self, rgb: np.ndarray, reg: Registration, skin: np.ndarray, cloth: np.ndarray, alpha: float
    ) -> np.ndarray:
        from ..geometry import TriMesh

        if alpha <= 0.0:
            return rgb.copy()
        k = self.kimono
        kimono = TriMesh(cloth[self.index], k.faces, k.uv, name="kimono", texture=k.texture)
        layer = self.renderer.render(
            kimono,
            camera=reg.camera(),
            size=(rgb.shape[1], rgb.shape[0]),
            background=None,
            occluders=[TriMesh(skin, self.faces, name="body")],
        )
        a = layer[..., 3:4].astype(np.float32) * (alpha / 255.0)
        out = rgb.astype(np.float32) * (1.0 - a) + layer[..., :3].astype(np.float32) * a
        return np.rint(out).astype(np.uint8)


class TryOn:
    """The whole mirror on one person. Use as a context manager, then `step(frame)` per frame, in order.

    body : a rigged body (default: the default body). garment : a kimono dressed on it in the rest pose (default:
    the default kimono dressed now at `settings.edge_cm`). constraints : the E/A table of the correction (default:
    the shipped one). compare : also simulate and render a second kimono driven by the uncorrected pose.
    render : draw the kimono over the frames (False: measure only).
    """

    def __init__(
        self,
        settings: TryOnSettings | None = None,
        *,
        body=None,  # noqa: ANN001
        garment=None,  # noqa: ANN001
        constraints=None,  # noqa: ANN001
        compare: bool = False,
        render: bool = True,
    ) -> None:
        from ..body import default_body
        from ..body.animate import animation_weights

        self.settings = s = settings or TryOnSettings()
        self.body = default_body() if body is None else body
        if garment is None:
            garment = default_simulation_kimono(self.body, edge_cm=s.edge_cm)
        weights = animation_weights(self.body)
        self.poses = PoseStage(s.filter)
        self.posing = BodyStage(self.body)
        self.corrector = OnlineCorrector(constraints)
        self.kimono = KimonoStage(self.body, garment, weights, s)
        self.raw_kimono = KimonoStage(self.body, garment, weights, s) if compare else None
        self.registrar: Registrar | None = None
        self.compositor = Compositor(self.body, garment) if render else None
        self.correct = s.correct  # the live window's `c` switches it
        self._last_pose_t: float | None = None
        self._last_t: float | None = None

    def __enter__(self) -> TryOn:
        self.poses.__enter__()
        return self

    def __exit__(self, *exc: object) -> None:
        self.poses.__exit__(*exc)
        if self.compositor is not None:
            self.compositor.close()

    def _dt(self, t: float) -> float:
        # the solver's step: the time since the last frame, kept to what it is stable and useful for
        dt = 1.0 / 30.0 if self._last_t is None else t - self._last_t
        self._last_t = t
        return float(np.clip(dt, 1.0 / 120.0, 1.0 / 10.0))

    def step(self, frame: Frame) -> MirrorFrame:
        """Process one frame: returns it with the kimono drawn over it, and its measures."""
        return self.dress(frame, self.observe(frame))

    def observe(self, frame: Frame) -> Observation:
        """The pose stage alone (a live mirror runs it in its own thread, overlapping the previous frame's
        simulation and render)."""
        t0 = time.perf_counter()
        people, raw, image, switched = self.poses(frame)
        return Observation(people, raw, image, time.perf_counter() - t0, switched)

    def dress(self, frame: Frame, seen: Observation) -> MirrorFrame:
        """Everything after the pose: correction, body, simulation, registration, render."""
        s = self.settings
        out = MirrorFrame(frame.index, frame.time_s, people=seen.people, stage_s={"pose": seen.seconds})
        timer = _Timer(out.stage_s)
        if self.registrar is None:
            self.registrar = Registrar((frame.rgb.shape[1], frame.rgb.shape[0]), s.focal_frames)
        dt = self._dt(frame.time_s)
        raw, image = seen.joints, seen.image
        if seen.switched:  # another person: their own kimono, blended on from the rest pose
            self._forget_person()
            out.switched = True
        if raw is None:
            self.corrector(None)
            since = None if self._last_pose_t is None else frame.time_s - self._last_pose_t
            out.alpha = 0.0 if since is None else max(0.0, 1.0 - since / s.fade_s)
            if since is not None and since >= s.fade_s:  # faded out: whoever comes next is dressed afresh
                self._forget_person()
                self.poses.reset()
                self._last_pose_t = None
        else:
            with timer("correct"):
                fixed = self.corrector(raw)  # always run, so that switching `correct` on mid-run starts smoothly
                if not self.correct:
                    fixed = raw
                out.corrected = self.correct and self.corrector.rotated
            with timer("body"):
                rot, joints = self.posing(fixed)
                raw_rot, raw_posed = (rot, joints) if fixed is raw else self.posing.pose(raw)
            with timer("simulate"):
                for stage, (r, j) in ((self.kimono, (rot, joints)), (self.raw_kimono, (raw_rot, raw_posed))):
                    if stage is None:
                        continue
                    try:
                        if stage.started:
                            stage.step(r, j, dt)
                        else:
                            stage.start(r, j, dt)
                    except ComputationError:
                        if not s.recover:
                            raise
                        stage.stop()
                        out.restarted = True
            with timer("register"):
                reg = self.registrar(raw_posed, image)
            if reg is not None:
                out.joint_residuals_px = reg.residual_px
                out.residual_px = reg.mean_residual_px
                out.residual_p95_px = float(np.nanpercentile(reg.residual_px, 95))
            out.posed = True
            out.alpha = 1.0
            out.raw_joints, out.joints = raw, fixed
            self._last_pose_t = frame.time_s
        if self.kimono.started and not out.restarted:
            out.strain_max = self.kimono.strain_max()
        with timer("render"):
            out.image = self._draw(frame, self.kimono, out.alpha)
            if self.raw_kimono is not None:
                out.raw_image = self._draw(frame, self.raw_kimono, out.alpha)
        return out

    def _forget_person(self) -> None:
        self.kimono.stop()
        if self.raw_kimono is not None:
            self.raw_kimono.stop()
        self.corrector(None)  # K' restarts
        self.posing.reset()
        if self.registrar is not None:
            self.registrar.last = None  # the camera's pose is fitted afresh on them

    def _draw(self, frame: Frame, stage: KimonoStage, alpha: float) -> np.ndarray | None:
        if self.compositor is None:
            return None
        reg = self.registrar.last if self.registrar is not None else None
        if reg is None or not stage.started or stage.skin is None:
            return frame.rgb.copy()
        return self.compositor(frame.rgb, reg, stage.skin, stage.positions, alpha)


class _Timer:
    def __init__(self, into: dict[str, float]) -> None:
        self.into = into

    def __call__(self, name: str) -> _Timer:
        self._name = name
        return self

    def __enter__(self) -> None:
        self._t0 = time.perf_counter()

    def __exit__(self, *exc: object) -> None:
        self.into[self._name] = self.into.get(self._name, 0.0) + time.perf_counter() - self._t0
