"""E by cloth simulation (SPEC §5.2): how far apart the knees, and the ankles, can go in each direction before the
kimono breaks.

For each joint pair (knee, ankle) and each angle θ of the horizontal line between the two joints (from the
left→right hip axis, 90° = one leg forward), the body starts standing in its rest pose with the kimono dressed on
it. Both legs, straight, turn about their hips so that the pair's joints move apart symmetrically about their rest
midpoint along θ: first to `start_m` apart within `lead_in_frames` (each joint straight from its rest place, so
that legs side by side do not pass through each other), then wider by `step_m` a frame. At the first
frame that breaks the kimono, the spread is bisected `bisections` times from the last frame that did not: each
try starts again from that frame's cloth (the simulation is reused, not replayed) and moves to the midpoint over
`settle_frames`. E(θ) is the largest spread that did not break.

The kimono breaks (`BreakThresholds`) when, after a frame:
- the cloth below the obi is torn: `torn_fraction` more of its edges stretched over `torn_strain` than standing;
- a leg shows outside the cloth: more than `uncovered_fraction` of either leg's skin points within `band_m` of the
  joint's height have no cloth of that band over them, seen from above:
  none ahead of a point along its skin's outward normal within `window_m` of that ray (`uncovered`: the leg shows
  through the kimono's opened front, or past its edge). A share, not one point: a point at the back of a knee
  uncovered for a single frame would set the knees' E 10 cm short. A joint below the hem (an ankle) is judged
  `hem_m` above the standing hem instead: the hem's lowest centimetres ride up over the back calf as one leg goes
  back, whatever the kimono's width (judged 3 cm above the hem, the ankles' E with one leg forward was 29-31 cm
  for the standard kimono and for one 7 cm wider, against 47-60 cm at the other angles);
- cloth is pushed into the body: `inside_fraction` more of the cloth below the obi is over `inside_m` inside the
  skin it lies on than standing.
A (the cross-section area of K) is the area of that hull at the joint's height on the dressed kimono, standing.
"""

from __future__ import annotations

import math
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field, fields

import numpy as np

from ..body.skinning import forward_kinematics, rotation_between
from ..errors import ComputationError, InputError, require_non_negative
from ..geometry.polygon import convex_hull
from ..skeleton import INDEX, descendants
from .simulate import KimonoSimulator, SimulationSettings

#: The joints each pair is measured at, and the leg chain each side's hip turns (everything below the hip).
_PAIR_JOINTS = {"knee": ("l_knee", "r_knee"), "ankle": ("l_ankle", "r_ankle")}


def _leg(side: str) -> list[int]:
    """The joints a hip turns: the hip itself and every joint below it."""
    hip = INDEX[f"{side}_hip"]
    return [hip, *descendants(hip)]


@dataclass(frozen=True)
class BreakThresholds:
    """When the kimono counts as broken (module docstring). Strains are fractions, lengths metres; hem_m: how far
    above the standing hem a joint below it is judged."""

    torn_strain: float = 0.10
    torn_fraction: float = 0.01
    band_m: float = 0.03
    hem_m: float = 0.08
    window_m: float = 0.03
    uncovered_fraction: float = 0.05
    inside_m: float = 0.005
    inside_fraction: float = 0.005

    def __post_init__(self) -> None:
        require_non_negative(self, "break threshold", *(f.name for f in fields(self)))
        if not all(getattr(self, name) <= 1.0 for name in ("torn_fraction", "uncovered_fraction", "inside_fraction")):
            raise InputError("break thresholds torn_fraction, uncovered_fraction and inside_fraction are shares <= 1")


@dataclass(frozen=True)
class CalibrationSettings:
    """How `calibrate` drives the legs (module docstring). theta_step_deg divides 180."""

    theta_step_deg: float = 15.0
    start_m: float = 0.15
    step_m: float = 0.02
    max_m: float = 1.0
    lead_in_frames: int = 15
    settle_frames: int = 3
    bisections: int = 3
    fps: float = 30.0
    workers: int = 2
    thresholds: BreakThresholds = field(default_factory=BreakThresholds)
    simulation: SimulationSettings = field(default_factory=SimulationSettings)

    def __post_init__(self) -> None:
        n = 180.0 / self.theta_step_deg if self.theta_step_deg > 0 else math.inf
        if not (math.isfinite(n) and abs(n - round(n)) < 1e-9):
            raise InputError(f"the angle step must divide 180 degrees, got {self.theta_step_deg}")
        if not (0 < self.start_m < self.max_m and self.step_m > 0):
            raise InputError("the spread needs 0 < start < max and a positive step (metres)")
        for name in ("lead_in_frames", "settle_frames", "bisections", "workers"):
            if int(getattr(self, name)) < (0 if name == "bisections" else 1):
                raise InputError(f"calibration setting {name} must be a positive integer")


def spread_pose(
    rest_joints: np.ndarray, pair: str, theta_deg: float, distance_m: float, blend: float = 1.0
) -> np.ndarray:
    """(J, 3, 3) world rotations of the rest body with both legs straight and turned about their hips so that the
    pair's joints stand `distance_m` apart horizontally along θ, symmetric about their rest midpoint (a joint the
    leg cannot reach is taken as far as the leg goes, horizontally). blend in [0, 1]: each joint that fraction
    of the straight way from its rest place to there."""
    jl, jr = (INDEX[j] for j in _PAIR_JOINTS[pair])
    hip_axis = rest_joints[INDEX["r_hip"]] - rest_joints[INDEX["l_hip"]]
    h = np.array([hip_axis[0], 0.0, hip_axis[2]])
    h /= np.linalg.norm(h)
    f = np.array([h[2], 0.0, -h[0]])  # forward = up × hip axis, as the posture correction measures θ
    t = math.radians(theta_deg)
    w = math.cos(t) * h + math.sin(t) * f
    if w @ h < 0:  # the same line; the right joint stays on the right (θ over 90°: the left leg forward)
        w = -w
    mid = 0.5 * (rest_joints[jl] + rest_joints[jr])
    rotations = np.tile(np.eye(3), (len(rest_joints), 1, 1))
    for side, joint, sign in (("l", jl, -1.0), ("r", jr, 1.0)):
        hip = rest_joints[INDEX[f"{side}_hip"]]
        bone = rest_joints[joint] - hip
        length = float(np.linalg.norm(bone))
        target = (1.0 - blend) * rest_joints[joint] + blend * (mid + sign * 0.5 * distance_m * w) - hip
        horizontal = np.array([target[0], 0.0, target[2]])
        r = min(float(np.linalg.norm(horizontal)), 0.999 * length)
        horizontal *= r / max(float(np.linalg.norm(horizontal)), 1e-12)
        new = horizontal + np.array([0.0, -math.sqrt(length * length - r * r), 0.0])
        rot = rotation_between(bone, new)
        for j in _leg(side):
            rotations[j] = rot
    return rotations


def uncovered(leg_xz: np.ndarray, normals_xz: np.ndarray, cloth_xz: np.ndarray, window_m: float) -> np.ndarray:
    """(n,) bool: the leg points (n, 2) that no cloth covers, seen from above: no cloth point (m, 2) lies ahead of
    the point along its skin's outward normal (n, 2; horizontal part) within `window_m` of that ray (the leg
    shows through the kimono's opened front, or past its edge)."""
    if len(cloth_xz) == 0:
        return np.ones(len(leg_xz), dtype=bool)
    n = normals_xz / np.maximum(np.linalg.norm(normals_xz, axis=1, keepdims=True), 1e-12)
    rel = cloth_xz[None, :, :] - leg_xz[:, None, :]  # (n, m, 2)
    along = (rel * n[:, None, :]).sum(axis=2)
    across = np.abs(rel[..., 0] * n[:, None, 1] - rel[..., 1] * n[:, None, 0])
    return ~((along > -0.002) & (across <= window_m)).any(axis=1)


def cross_section_area(cloth: np.ndarray, height_m: float, band_m: float = 0.03) -> float:
    """Area (m²) of the convex hull, seen from above, of the cloth vertices (V, 3) within band_m of height_m."""
    near = cloth[np.abs(cloth[:, 1] - height_m) <= band_m][:, [0, 2]]
    hull = convex_hull(near)
    if hull is None:
        raise ComputationError("calibration", f"no cloth around the legs at height {height_m:.2f} m")
    return float(hull.volume)  # a 2-D hull's volume is its area


class _Spread:
    """One pair and angle: the simulator and what breaking means for it."""

    def __init__(self, body, garment, pair: str, theta_deg: float, settings: CalibrationSettings) -> None:  # noqa: ANN001
        from ..body.animate import animation_weights
        from ..dressing.kimono import obi_band

        self.body, self.pair, self.theta, self.s = body, pair, theta_deg, settings
        self.sim = KimonoSimulator(body, garment, animation_weights(body), settings.simulation)
        self.rest = body.rig.joints
        low, _ = obi_band(body)
        skirt = self.sim.state.positions[:, 1] < low
        self.skirt = skirt
        e = self.sim.model.edges
        self.skirt_edges = skirt[e[:, 0]] & skirt[e[:, 1]]
        w = body.rig.weights
        self.leg_vertices = {side: np.flatnonzero(w[:, _leg(side)].sum(axis=1) > 0.5) for side in ("l", "r")}
        #: the cloth's lowest band: a joint below the hem (an ankle under a kimono worn above it) is checked there
        self.hem_y = float(self.sim.state.positions[:, 1].min()) + settings.thresholds.hem_m
        jl, jr = (INDEX[j] for j in _PAIR_JOINTS[pair])
        self.distance = float(np.linalg.norm((self.rest[jr] - self.rest[jl])[[0, 2]]))
        self.baseline = self._torn_inside(body.mesh.vertices)

    def pose(self, distance_m: float, blend: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
        """Rotations and joints of the spread `distance_m` apart; `blend` < 1: that far from standing to it."""
        rot = spread_pose(self.rest, self.pair, self.theta, distance_m, blend)
        return rot, forward_kinematics(self.rest, rot, self.rest[INDEX["pelvis"]])

    def lead_in(self, distance_m: float, frames: int) -> np.ndarray:
        """From standing to the spread `distance_m` over `frames` frames (the joints' paths straight from their
        rest places, so that legs side by side do not pass through each other); the skin at the end."""
        for k in range(1, frames + 1):
            skin = self.sim.advance(*self.pose(distance_m, k / frames), 1.0 / self.s.fps)
        self.distance = distance_m
        return skin

    def move(self, distance_m: float, frames: int) -> np.ndarray:
        """Spread linearly from the current distance to `distance_m` over `frames` frames; the skin at the end."""
        start = self.distance
        for k in range(1, frames + 1):
            skin = self.sim.advance(*self.pose(start + (distance_m - start) * k / frames), 1.0 / self.s.fps)
        self.distance = distance_m
        return skin

    def _torn_inside(self, skin: np.ndarray) -> tuple[float, int]:
        """(fraction of the skirt's edges stretched over the threshold, skirt vertices too deep inside the skin)."""
        t = self.s.thresholds
        x = self.sim.state.positions
        e = self.sim.model.edges[self.skirt_edges]
        stretch = np.linalg.norm(x[e[:, 1]] - x[e[:, 0]], axis=1) / self.sim.model.rest_lengths[self.skirt_edges] - 1
        # inside the skin it lies on (the collision's tracked signed distance): where the legs' skins overlap
        # each other, cloth on one thigh lies inside the other by any global test
        inside = int((self.sim.state.contacts.distance[self.skirt] < -t.inside_m).sum())
        return float(np.mean(stretch > t.torn_strain)), inside

    def broken(self, skin: np.ndarray) -> str | None:
        """Why the kimono is broken now (a few words), or None. Tearing and cloth inside count beyond what the
        standing kimono had (a dressed kimono starts with a few strained edges)."""
        t = self.s.thresholds
        torn, inside = self._torn_inside(skin)
        if torn - self.baseline[0] > t.torn_fraction:
            return "torn"
        x = self.sim.state.positions
        _, joints = self.pose(self.distance)
        normals = self.sim.moving.surface.vertex_normals
        for side, jname in zip(("l", "r"), _PAIR_JOINTS[self.pair], strict=True):
            y = max(float(joints[INDEX[jname], 1]), self.hem_y)
            cloth = x[np.abs(x[:, 1] - y) <= t.band_m][:, [0, 2]]
            leg = self.leg_vertices[side]
            leg = leg[(np.abs(skin[leg, 1] - y) <= t.band_m) & (np.abs(normals[leg, 1]) < 0.7)]  # its sides
            if len(leg):
                shows = uncovered(skin[leg][:, [0, 2]], normals[leg][:, [0, 2]], cloth, t.window_m)
                if shows.mean() > t.uncovered_fraction:
                    return "leg outside"
        if inside - self.baseline[1] > t.inside_fraction * int(self.skirt.sum()):
            return "pushed inside"
        return None


def _state(sim: KimonoSimulator):  # noqa: ANN202
    s = sim.state
    return s.positions.copy(), s.velocities.copy(), sim.moving.ends.copy(), sim.moving.surface, sim.moving.hold_now


def _restore(sim: KimonoSimulator, saved) -> None:  # noqa: ANN001
    positions, velocities, ends, surface, hold_now = saved
    sim.state.positions[:] = positions
    sim.state.velocities[:] = velocities
    sim.moving.ends = ends.copy()
    sim.moving.surface = surface
    sim.moving.hold_now = hold_now
    from ..cloth._collide import track

    track(sim.model, sim.state, surface)


def largest_spread(body, garment, pair: str, theta_deg: float, settings: CalibrationSettings) -> dict:  # noqa: ANN001
    """E for one pair and angle (module docstring): {"theta_deg", "max_distance_m", "broke" (why the first
    too-wide spread broke, or None when none up to max_m did), "frames"}."""
    s = settings
    run = _Spread(body, garment, pair, theta_deg, s)
    skin = run.lead_in(s.start_m, s.lead_in_frames)
    frames = s.lead_in_frames
    why = run.broken(skin)
    if why is not None:
        return {"theta_deg": theta_deg, "max_distance_m": s.start_m, "broke": why, "frames": frames}
    good, bad = s.start_m, None
    saved = _state(run.sim)
    while bad is None and good < s.max_m - 1e-9:
        d = min(good + s.step_m, s.max_m)
        skin = run.move(d, 1)
        frames += 1
        why = run.broken(skin)
        if why is None:
            good, saved = d, _state(run.sim)
        else:
            bad, first_why = d, why
    if bad is None:
        return {"theta_deg": theta_deg, "max_distance_m": good, "broke": None, "frames": frames}
    for _ in range(s.bisections):
        mid = 0.5 * (good + bad)
        _restore(run.sim, saved)
        run.distance = good
        skin = run.move(mid, s.settle_frames)
        frames += s.settle_frames
        if run.broken(skin) is None:
            good, saved = mid, _state(run.sim)
        else:
            bad = mid
    return {"theta_deg": theta_deg, "max_distance_m": good, "broke": first_why, "frames": frames}


def _job(args) -> dict:  # noqa: ANN001
    return largest_spread(*args)


@dataclass
class Calibration:
    """What `calibrate` found. table : the E/A table (source "calibrated"). spreads : per pair, one dict per angle
    (`largest_spread`). seconds : wall time."""

    table: object
    spreads: dict[str, list[dict]]
    seconds: float


def calibrate(
    garment,  # noqa: ANN001 - a kimono dressed on `body` (DressedGarment or GarmentFile)
    body=None,  # noqa: ANN001
    *,
    settings: CalibrationSettings | None = None,
    label: str = "kimono",
    progress: bool | None = None,
) -> Calibration:
    """E(θ) for the knees and the ankles by simulation, and A from the dressed kimono (module docstring)."""
    from .._progress import progress as bar
    from ..body import default_body
    from ..dressing.export import as_garment_file
    from ..pose import ConstraintTable, PairLimit

    s = settings or CalibrationSettings()
    body = default_body() if body is None else body
    g = as_garment_file(garment)
    t0 = time.perf_counter()
    thetas = np.arange(0.0, 180.0 - 1e-9, s.theta_step_deg)
    jobs = [(body, g, pair, float(t), s) for pair in _PAIR_JOINTS for t in thetas]
    if s.workers > 1:
        import multiprocessing

        # spawned, not forked: the dressing has run OpenMP threads in this process (forking them aborts)
        with ProcessPoolExecutor(max_workers=s.workers, mp_context=multiprocessing.get_context("spawn")) as pool:
            results = list(bar(pool.map(_job, jobs), total=len(jobs), desc="calibrating", enabled=progress))
    else:
        results = [_job(j) for j in bar(jobs, total=len(jobs), desc="calibrating", enabled=progress)]
    spreads: dict[str, list[dict]] = {pair: [] for pair in _PAIR_JOINTS}
    for (_, _, pair, _, _), r in zip(jobs, results, strict=True):
        spreads[pair].append(r)
    limits = {}
    rest = body.rig.joints
    hem = float(g.positions[:, 1].min()) + s.thresholds.hem_m  # an ankle below the hem: the hem's section
    for pair, (jl, jr) in _PAIR_JOINTS.items():
        height = max(0.5 * (rest[INDEX[jl], 1] + rest[INDEX[jr], 1]), hem)
        limits[pair] = PairLimit(
            theta_deg=thetas,
            max_distance_m=np.array([r["max_distance_m"] for r in spreads[pair]]),
            area_m2=cross_section_area(g.positions, height, s.thresholds.band_m),
        )
    table = ConstraintTable(knee=limits["knee"], ankle=limits["ankle"], source="calibrated", garment=label)
    return Calibration(table, spreads, time.perf_counter() - t0)


def plot_constraints(table, path, *, against=None, title: str | None = None):  # noqa: ANN001, ANN201
    """A PNG of E(θ) for the knees and the ankles as polar plots (θ over the full circle: a line at θ is the same
    line at θ + 180°), with `against` (another table, e.g. the geometric estimate) dashed. Returns the path."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from .._files import atomic_path

    fig, axes = plt.subplots(1, 2, subplot_kw={"projection": "polar"}, figsize=(10, 5.8), dpi=110)
    for ax, pair in zip(axes, ("knee", "ankle"), strict=True):
        for t, style, label in ((table, "-", table.source), (against, "--", getattr(against, "source", ""))):
            if t is None:
                continue
            lim = t.pair(pair)
            th = np.deg2rad(np.concatenate([lim.theta_deg, lim.theta_deg + 180.0, lim.theta_deg[:1] + 360.0]))
            e = np.concatenate([lim.max_distance_m, lim.max_distance_m, lim.max_distance_m[:1]]) * 100
            ax.plot(
                th,
                e,
                style,
                lw=1.8,
                marker="o" if style == "-" else None,
                ms=3,
                label=f"{label}, A {lim.area_m2 * 1e4:.0f} cm²",
            )
        ax.set_title(f"{pair}s: E(θ), cm\n0° = left→right hip axis, 90° = right leg forward", fontsize=9, pad=14)
        ax.legend(loc="upper center", fontsize=7, bbox_to_anchor=(0.5, -0.06))
    if title:
        fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png")
    plt.close(fig)
    return path
