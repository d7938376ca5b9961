"""Kimono posture correction (SPEC §5.3), its invariants and its quality measures (SPEC §6).

For each frame, in order, knees first and then ankles (on the knee-corrected pose):
1. K from the current pose: centre between the pair's horizontal positions, long axis along them, semi-major
   a = E(θ)/2, semi-minor b = A/(π a). If the pair's horizontal distance is within E(θ) the frame is left exactly as
   it is (for this pair).
2. Otherwise the target is the joint of the pair farther (horizontally) from the pelvis. K' is K of the previous
   frame's *corrected* pose (the current K on the first frame or after a frame without a pose). Where the SPEC is
   silent: if that joint is already inside K' but the other is not, the other is the target — rotating a joint that
   is already inside does nothing, and the pair would stay apart (a one-frame spike in the plots).
3. The segment above the target (thigh for a knee, shin for an ankle) and everything below it rotate about the
   axis e = normalise(segment × w) through the segment's start (hip, knee), w being the horizontal direction from
   the target toward its closest point on K''s ellipse (up × w when the segment is parallel to w), by the smallest
   angle in (0°, 180°] that puts the target inside the vertical cylinder through K' (sampled, then bisected to
   0.1 mm of target motion); if no angle does, by the angle that comes closest.

Plausibility rules (where the SPEC is silent; without them a knee raise swaps the ankles' sides, draws the right
leg to the left foot and snaps a knee 26 cm between frames):
4. Which joint: the leg rotated in the previous frame stays the target while the pair needs correcting. Switching
   legs would drop the other leg's correction in one frame (its whole size as a jump).
5. Which angle: only angles that keep every moved leg joint on its raw side of the sagittal plane (through the
   pelvis, normal along the hip axis; within `SIDE_MARGIN_M`) and keep the target within its raw motion plus
   `MAX_JUMP_M` of its previous corrected place (the ankle pass checks the ankle, heel and toe; the knee pass the
   knee, since the ankle pass can still turn the shin) count. The smallest such angle that reaches K' is taken
   (status "rotated into K'", or CONSTRAINED when a smaller angle reached K' but broke a rule); if none reaches
   it, the allowed angle closest to K' (LIMITED), or, when no angle about this frame's axis is allowed, the part
   of the turn back toward the previous frame's segment direction that jumps least.
6. Easing out: a frame that needs no rotation, yet where dropping the previous frame's correction (or the knee
   pass's move of the shin) at once would jump past the allowance, turns the segment toward the previous
   frame's direction by the smallest part that keeps within it (EASED). So a correction fades over a few frames
   instead of snapping back. Both legs are checked, also in a frame that rotates the other one.
The SPEC's invariants hold as before, with frames touched by the rules counted as touched; its continuity bound
assumes the smallest angle and is checked where that was taken. `correct_poses(..., max_jump_m=inf,
side_margin_m=inf)` is the SPEC's rotation alone (with rule 4).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from ..skeleton import BONES, INDEX, JOINTS, descendants
from . import _kernels as K
from ._constraints import PAIRS, ConstraintTable, default_constraints
from ._sequence import PoseSequence

PAIR_JOINTS = np.array([[INDEX["l_knee"], INDEX["r_knee"]], [INDEX["l_ankle"], INDEX["r_ankle"]]], dtype=np.int64)
START_JOINTS = np.array([[INDEX["l_hip"], INDEX["r_hip"]], [INDEX["l_knee"], INDEX["r_knee"]]], dtype=np.int64)


def _moved_table() -> np.ndarray:
    """(2, 2, 4) int64: the target and the joints below it, per pair and side (-1 padded)."""
    out = -np.ones((2, 2, 4), dtype=np.int64)
    for p in range(2):
        for s in range(2):
            t = JOINTS[PAIR_JOINTS[p, s]]
            below = [t] + [JOINTS[j] for j in descendants(INDEX[t])]
            out[p, s, : len(below)] = [INDEX[j] for j in below]
    return out


MOVED = _moved_table()
#: Status codes per frame and pair (see `Correction.status`).
STATUS = {
    K.INVALID: "no pose",
    K.INSIDE: "inside K",
    K.ROTATED: "rotated into K'",
    K.ALREADY_INSIDE: "both joints already inside K'",
    K.CLOSEST: "rotated to the closest angle (K' out of reach)",
    K.UNREACHABLE: "K' out of reach, not rotated",
    K.CONSTRAINED: "rotated into K' by a larger angle (the smallest would swap sides or jump)",
    K.LIMITED: "rotated toward K' as far as the side and jump rules allow",
    K.EASED: "inside, part of the previous frame's rotation kept (no jump)",
}
#: A moved joint may move this much more than its raw motion between consecutive frames, metres.
MAX_JUMP_M = 0.05
#: A leg joint counts as on the other side of the sagittal plane only beyond this, metres: feet walk close to the
#: plane, and a raw joint a few millimetres from it has no side worth keeping.
SIDE_MARGIN_M = 0.02


@dataclass
class Correction:
    """The result of `correct_poses`.

    Attributes
    ----------
    poses : the corrected sequence (positions corrected; raw_positions, corrected and constraints filled).
    target : (n, 2) int64, per frame and pair (knee, ankle): the target joint index, -1 when the pair was inside K.
    angle_rad : (n, 2) float64, the rotation applied, radians (0 when none).
    residual_m : (n, 2) float64, the target's horizontal distance outside K' after correction, metres (0 inside).
    regions : (n, 2, 6) float64, K' per frame and pair where a target was chosen: centre x, z (m), unit long
        axis x, z, semi-axes a, b (m). Undefined elsewhere.
    status : (n, 2) int8, see `STATUS`.
    seconds : wall time of the correction itself (the kernel), seconds.
    stage_input : (n, 2, 3) float64, the target's position when its pass began (for ankles: after the knee pass),
        metres; NaN where no target was chosen.
    """

    poses: PoseSequence
    target: np.ndarray
    angle_rad: np.ndarray
    residual_m: np.ndarray
    regions: np.ndarray
    status: np.ndarray
    seconds: float
    stage_input: np.ndarray

    @property
    def rotated(self) -> np.ndarray:
        """(n, 2) bool: a segment was rotated for this frame and pair."""
        return np.isin(self.status, K.ROTATING)


def _tables(constraints: ConstraintTable) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    tts, ees = [], []
    for name in PAIRS:
        tt, ee = constraints.pair(name).periodic_table()
        tts.append(tt)
        ees.append(ee)
    m = max(len(t) for t in tts)
    # pad the shorter table by repeating its last entry (beyond π, never reached after the modulo)
    tt = np.array([np.pad(t, (0, m - len(t)), constant_values=t[-1] + 1.0) for t in tts])
    ee = np.array([np.pad(e, (0, m - len(e)), mode="edge") for e in ees])
    area = np.array([constraints.pair(n).area_m2 for n in PAIRS])
    return tt, ee, area


def correct_poses(
    poses: PoseSequence,
    constraints: ConstraintTable | None = None,
    *,
    tolerance_m: float = 1e-4,
    samples: int = 64,
    max_jump_m: float = MAX_JUMP_M,
    side_margin_m: float = SIDE_MARGIN_M,
) -> Correction:
    """Correct a pose sequence for a kimono (SPEC §5.3); the input is not modified.

    Parameters
    ----------
    poses : the raw (possibly filtered) poses.
    constraints : E and A per pair; default the shipped table calibrated by simulation (`default_constraints()`).
    tolerance_m : bisection stops when the target moves less than this between the bracket's ends, metres.
    samples : angles sampled over (0°, 180°] to bracket the smallest one.
    max_jump_m : a rotated joint may move at most its raw motion plus this between consecutive frames, metres.
    side_margin_m : a rotated leg joint may end at most this far on the other side of the sagittal plane than its
        raw position, metres. `inf` for both gives the SPEC's rotation without the plausibility rules.
    """
    table = constraints if constraints is not None else default_constraints()
    rules = _rules(table, tolerance_m, samples, max_jump_m, side_margin_m)
    pos = np.ascontiguousarray(poses.positions, dtype=np.float64)
    n = len(pos)
    rows = _Rows(n, pos.copy())
    t0 = time.perf_counter()
    K.correct_frames(pos, np.ascontiguousarray(poses.valid), *rules, *rows.outputs(), 0)
    seconds = time.perf_counter() - t0
    target, status = rows.target, rows.status
    rotated = np.isin(status, K.ROTATING)
    corrected = [tuple(JOINTS[target[f, p]] for p in range(2) if rotated[f, p]) for f in range(n)]
    src = dict(poses.source)
    result = replace(
        poses.copy(),
        positions=rows.out,
        raw_positions=pos.copy(),
        corrected=corrected,
        constraints=table,
        source=src,
    )
    return Correction(result, target, rows.angle, rows.residual, rows.regions, status, seconds, rows.stage_input)


def _rules(table: ConstraintTable, tolerance_m: float, samples: int, max_jump_m: float, side_margin_m: float) -> tuple:
    """The kernel's fixed arguments between the poses and the outputs (checked)."""
    if not (tolerance_m > 0):
        raise ValueError(f"tolerance_m must be positive, got {tolerance_m}")
    if samples < 4:
        raise ValueError(f"samples must be at least 4, got {samples}")
    tt, ee, area = _tables(table)
    return (
        tt, ee, area, PAIR_JOINTS, START_JOINTS, MOVED, INDEX["l_hip"], INDEX["r_hip"], INDEX["pelvis"],
        float(tolerance_m), int(samples), float(max_jump_m), float(side_margin_m),
    )  # fmt: skip


class _Rows:
    """The kernel's per-frame outputs for n frames (see `Correction`); `out` starts as the input poses."""

    def __init__(self, n: int, out: np.ndarray) -> None:
        self.out = out
        self.target = -np.ones((n, 2), dtype=np.int64)
        self.angle = np.zeros((n, 2))
        self.residual = np.zeros((n, 2))
        self.regions = np.full((n, 2, 6), np.nan)
        self.status = np.full((n, 2), K.INVALID, dtype=np.int8)
        self.stage_input = np.full((n, 2, 3), np.nan)
        self.axes = np.zeros((n, 2, 3))

    def outputs(self) -> tuple:
        return self.out, self.target, self.angle, self.residual, self.regions, self.status, self.stage_input, self.axes

    def shift(self) -> None:
        """Row 1 becomes row 0 (the previous frame of a two-row window)."""
        for a in self.outputs():
            a[0] = a[1]


class OnlineCorrector:
    """`correct_poses` one frame at a time, for a live camera: each call corrects a frame from the previous frame's
    result, exactly as the whole-sequence correction would (the same kernel; equal results, tested).

    corrector = OnlineCorrector()             # the shipped constraints
    fixed = corrector(joints)                 # (J, 3) raw joints, metres, Y up -> (J, 3) corrected (a new array)
    corrector(None)                           # a frame without a pose: the next one starts afresh
    corrector.status, corrector.target        # (2,) this frame's status and target per pair (knees, ankles)
    """

    def __init__(
        self,
        constraints: ConstraintTable | None = None,
        *,
        tolerance_m: float = 1e-4,
        samples: int = 64,
        max_jump_m: float = MAX_JUMP_M,
        side_margin_m: float = SIDE_MARGIN_M,
    ) -> None:
        self.constraints = constraints if constraints is not None else default_constraints()
        self._rules = _rules(self.constraints, tolerance_m, samples, max_jump_m, side_margin_m)
        self._raw = np.zeros((2, len(JOINTS), 3))
        self._valid = np.zeros(2, dtype=bool)
        self._rows = _Rows(2, np.zeros((2, len(JOINTS), 3)))

    def __call__(self, joints: np.ndarray | None) -> np.ndarray | None:
        rows = self._rows
        rows.shift()
        self._raw[0] = self._raw[1]
        self._valid[0] = self._valid[1]
        if joints is None:
            self._valid[1] = False
            rows.status[1] = K.INVALID
            rows.target[1] = -1
            return None
        q = np.asarray(joints, dtype=np.float64)
        self._raw[1] = q
        rows.out[1] = q
        self._valid[1] = True
        K.correct_frames(self._raw, self._valid, *self._rules, *rows.outputs(), 1)
        return rows.out[1].copy()

    @property
    def status(self) -> np.ndarray:
        """(2,) int8 the last frame's status per pair (knees, ankles): see `STATUS`."""
        return self._rows.status[1].copy()

    @property
    def target(self) -> np.ndarray:
        """(2,) int64 the last frame's target joint per pair, -1 where none."""
        return self._rows.target[1].copy()

    @property
    def rotated(self) -> bool:
        """The last frame had a leg segment rotated."""
        return bool(np.isin(self._rows.status[1], K.ROTATING).any())


# ------------------------------------------------------------------------------------------- regions in numpy


def regions_of(positions: np.ndarray, constraints: ConstraintTable, pair: str) -> tuple[np.ndarray, np.ndarray]:
    """K of every pose (vectorised numpy, the same definition as the kernel).

    Returns ((n, 6) ellipses: centre x, z, unit axis x, z, a, b; (n,) horizontal distance of the pair minus E(θ)).
    """
    p = PAIRS.index(pair)
    jl, jr = PAIR_JOINTS[p]
    lim = constraints.pair(pair)
    q = np.asarray(positions, dtype=np.float64)
    h = q[:, INDEX["r_hip"], ::2] - q[:, INDEX["l_hip"], ::2]
    hn = np.linalg.norm(h, axis=1, keepdims=True)
    h = np.where(hn < 1e-12, np.array([-1.0, 0.0]), h / np.where(hn < 1e-12, 1.0, hn))
    fwd = np.stack([h[:, 1], -h[:, 0]], axis=1)
    u = q[:, jr, ::2] - q[:, jl, ::2]
    d = np.linalg.norm(u, axis=1)
    small = d < 1e-12
    un = np.where(small[:, None], h, u / np.where(small, 1.0, d)[:, None])
    theta = np.where(small, 0.0, np.arctan2((un * fwd).sum(1), (un * h).sum(1)))
    e = lim.max_distance(theta)
    a = 0.5 * e
    c = 0.5 * (q[:, jl, ::2] + q[:, jr, ::2])
    ell = np.column_stack([c, un, a, lim.area_m2 / (np.pi * a)])
    return ell, d - e


def inside_values(points_xz: np.ndarray, ell: np.ndarray) -> np.ndarray:
    """(ξ/a)² + (ζ/b)² − 1 of (n, 2) horizontal points against (n, 6) ellipses (≤ 0 inside)."""
    d = points_xz - ell[:, :2]
    xi = d[:, 0] * ell[:, 2] + d[:, 1] * ell[:, 3]
    zeta = d[:, 0] * ell[:, 3] - d[:, 1] * ell[:, 2]
    return (xi / ell[:, 4]) ** 2 + (zeta / ell[:, 5]) ** 2 - 1.0


def ellipse_motion(e0: np.ndarray, e1: np.ndarray, samples: int = 64) -> np.ndarray:
    """(n,) how far the boundary of ellipses (n, 6) e0 moves to e1: the largest distance between points of the
    same parameter t (an upper bound of the Hausdorff distance), metres."""
    t = np.linspace(0.0, 2 * np.pi, samples, endpoint=False)

    def pts(e: np.ndarray) -> np.ndarray:
        u = e[:, None, 2:4]
        v = np.stack([e[:, 3], -e[:, 2]], axis=1)[:, None, :]
        return (
            e[:, None, :2]
            + e[:, None, 4:5] * np.cos(t)[None, :, None] * u
            + e[:, None, 5:6] * np.sin(t)[None, :, None] * v
        )

    return np.linalg.norm(pts(e1) - pts(e0), axis=2).max(axis=1)


# ------------------------------------------------------------------------------------- invariants and measures


def _pass_input(c: Correction, pi: int, frames: np.ndarray, joints: np.ndarray) -> np.ndarray:
    """(k, 3) position of `joints` at `frames` when pass `pi` began: raw for knees; after the knee pass for ankles
    (the ankle pass moves only its target, so a non-target ankle's final position is its pass input)."""
    if pi == 0:
        return c.poses.raw_positions[frames, joints]  # type: ignore[index]
    was_target = c.target[frames, pi] == joints
    return np.where(was_target[:, None], c.stage_input[frames, pi], c.poses.positions[frames, joints])


def check_invariants(
    correction: Correction, *, length_tol_m: float = 1e-9, inside_tol: float = 1e-9, motion_tol_m: float = 1e-9
) -> dict[str, Any]:
    """Check SPEC §5.3's invariants on a correction, recomputing K' from the output (numpy, not the kernel).

    1. untouched frames are bit-identical to the input;
    2. every target rotated into K' is inside K' (K' recomputed from the previous corrected frame);
    3. bone lengths are unchanged (within `length_tol_m`);
    4. continuity: for a target rotated at τ with valid τ−1 and τ−2, |q'(τ) − q'(τ−1)| ≤ |q(τ) − q(τ−1)| +
       motion of K' from τ−1 to τ (+ `motion_tol_m`), q being the target's position when its pass began (raw for
       knees, after the knee pass for ankles) and the motion of K' the largest displacement of its boundary points
       (`ellipse_motion`). Frames where the target was out of reach (at τ or τ−1) are left out: the SPEC lets
       those end outside K'. The same bound on horizontal motion only is reported as `continuity_broken_horizontal`.

    Returns a dict with the number of violations of each (`untouched_changed`, `targets_outside`,
    `lengths_changed`, `continuity_broken`), the continuity checks made, the largest bone-length change (m), the worst
    continuity excess (m), the unreachable count, and `ok` (all violation counts zero).
    """
    c = correction
    poses = c.poses
    q, p, valid = poses.positions, poses.raw_positions, poses.valid
    table = poses.constraints
    if p is None or table is None:
        raise ValueError("check_invariants needs a corrected sequence")
    n = len(q)
    rotated = c.rotated
    touched = rotated.any(axis=1)
    same = np.array([np.array_equal(q[f], p[f], equal_nan=True) for f in range(n)])
    untouched_changed = int((~touched & ~same).sum())
    # Out of reach, or reached only by a larger angle than the smallest: the SPEC's continuity argument assumes the
    # smallest angle, so these frames are left out of that check (the side and jump rules bound them instead).
    reach_fail = np.isin(c.status, (K.CLOSEST, K.UNREACHABLE, K.CONSTRAINED, K.LIMITED, K.EASED))

    targets_outside = 0
    continuity_broken = 0
    continuity_broken_h = 0
    continuity_checked = 0
    worst_excess = 0.0
    prev_ok = np.zeros(n, dtype=bool)
    prev_ok[1:] = valid[1:] & valid[:-1]
    for pi, name in enumerate(PAIRS):
        # K' of every frame from the previous corrected frame, or the one stored (first frame / after a gap)
        ell_prev = np.full((n, 6), np.nan)
        ell_prev[1:] = regions_of(q[:-1], table, name)[0]
        use_stored = ~prev_ok & rotated[:, pi]
        ell_prev[use_stored] = c.regions[use_stored, pi]
        sel = np.flatnonzero(np.isin(c.status[:, pi], (K.ROTATED, K.CONSTRAINED)))
        if len(sel):
            tj = c.target[sel, pi]
            g = inside_values(q[sel, tj][:, ::2], ell_prev[sel])
            targets_outside += int((g > inside_tol).sum())
        sel = np.flatnonzero(rotated[:, pi])
        sel = sel[sel >= 2]
        sel = sel[valid[sel - 1] & valid[sel - 2] & ~reach_fail[sel, pi] & ~reach_fail[sel - 1, pi]]
        if len(sel):
            tj = c.target[sel, pi]
            km = ellipse_motion(ell_prev[sel - 1], ell_prev[sel])
            dp = _pass_input(c, pi, sel, tj) - _pass_input(c, pi, sel - 1, tj)
            dq = q[sel, tj] - q[sel - 1, tj]
            excess = np.linalg.norm(dq, axis=1) - (np.linalg.norm(dp, axis=1) + km)
            excess_h = np.linalg.norm(dq[:, ::2], axis=1) - (np.linalg.norm(dp[:, ::2], axis=1) + km)
            continuity_checked += len(sel)
            continuity_broken += int((excess > motion_tol_m).sum())
            continuity_broken_h += int((excess_h > motion_tol_m).sum())
            worst_excess = max(worst_excess, float(excess.max()))
    swapped, jumps, worst_jump = plausibility(q, p, valid)
    bones = np.array([[INDEX[a], INDEX[b]] for a, b in BONES])
    if valid.any():
        len_q = np.linalg.norm(q[valid][:, bones[:, 1]] - q[valid][:, bones[:, 0]], axis=2)
        len_p = np.linalg.norm(p[valid][:, bones[:, 1]] - p[valid][:, bones[:, 0]], axis=2)
        dlen = float(np.abs(len_q - len_p).max())
        lengths_changed = int((np.abs(len_q - len_p) > length_tol_m).sum())
    else:
        dlen, lengths_changed = 0.0, 0
    return {
        "ok": untouched_changed == 0
        and targets_outside == 0
        and lengths_changed == 0
        and continuity_broken == 0
        and swapped == 0
        and jumps == 0,
        "untouched_changed": untouched_changed,
        "targets_outside": targets_outside,
        "lengths_changed": lengths_changed,
        "max_length_change_m": dlen,
        "continuity_checked": continuity_checked,
        "continuity_broken": continuity_broken,
        "continuity_broken_horizontal": continuity_broken_h,
        "worst_continuity_excess_m": max(0.0, worst_excess),
        "unreachable": int(np.isin(c.status, (K.CLOSEST, K.UNREACHABLE, K.LIMITED)).sum()),
        "constrained": int((c.status == K.CONSTRAINED).sum()),
        "sides_swapped": swapped,
        "jumps_over_limit": jumps,
        "worst_jump_excess_m": worst_jump,
    }


_LEG_JOINTS = np.array([INDEX[j] for j in JOINTS if j[2:] in ("knee", "ankle", "heel", "toe")])


def plausibility(
    positions: np.ndarray, raw: np.ndarray, valid: np.ndarray, *, max_jump_m: float = MAX_JUMP_M, tol_m: float = 1e-9
) -> tuple[int, int, float]:
    """The corrections' plausibility (issue: legs held by a kimono still look like legs).

    Returns (frames where a corrected leg joint is more than SIDE_MARGIN_M on the other side of the sagittal
    plane — through the pelvis, normal along the hip axis — than its raw position; frame transitions where a joint
    moves more than its raw motion plus `max_jump_m`; the largest such excess, metres, 0 when none).
    """
    pel = raw[:, INDEX["pelvis"], ::2]
    n = raw[:, INDEX["l_hip"], ::2] - raw[:, INDEX["r_hip"], ::2]
    n = n / np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-12)
    side_raw = ((raw[:, _LEG_JOINTS, ::2] - pel[:, None]) * n[:, None]).sum(-1)
    side_now = ((positions[:, _LEG_JOINTS, ::2] - pel[:, None]) * n[:, None]).sum(-1)
    crossed = (side_raw * side_now < 0) & (np.abs(side_now) > SIDE_MARGIN_M)
    swapped = int((crossed.any(axis=1) & valid).sum())
    ok = valid[1:] & valid[:-1]
    if not ok.any():
        return swapped, 0, 0.0
    moved_now = np.linalg.norm(np.diff(positions, axis=0), axis=2)[ok]
    moved_raw = np.linalg.norm(np.diff(raw, axis=0), axis=2)[ok]
    excess = (moved_now - moved_raw - max_jump_m).max(axis=1)
    return swapped, int((excess > tol_m).sum()), max(0.0, float(excess.max()))


def _max_jumps(positions: np.ndarray, valid: np.ndarray) -> np.ndarray:
    """(J,) largest frame-to-frame displacement of each joint over consecutive valid frames, metres."""
    ok = valid[1:] & valid[:-1]
    if not ok.any():
        return np.zeros(positions.shape[1])
    d = np.linalg.norm(positions[1:] - positions[:-1], axis=2)[ok]
    return d.max(axis=0)


def exceedance(poses: PoseSequence) -> dict[str, dict[str, float]]:
    """Per pair, how the corrected pose still exceeds E(θ) of its own frame (the correction aims at K' of the
    previous frame, so a pair can end inside K' yet apart by more than this frame's E): frames, and the largest and
    mean excess over those frames, cm."""
    out = {}
    v = poses.valid
    for name in PAIRS:
        _, excess = regions_of(poses.positions[v], poses.constraints, name)
        over = excess[excess > 1e-6]
        out[name] = {
            "frames": int(len(over)),
            "max_cm": round(float(over.max()) * 100, 2) if len(over) else 0.0,
            "mean_cm": round(float(over.mean()) * 100, 2) if len(over) else 0.0,
        }
    return out


def correction_measures(correction: Correction) -> dict[str, Any]:
    """SPEC §6 pose-correction measures as a JSON-ready dict.

    fraction of valid frames corrected, corrections per pair, residual outside distance of the targets rotated into
    K' (mm, 0 expected), how far short of K' the targets stayed where it was out of reach or only reachable by
    breaking the side and jump rules (`short_of_region`), how far pairs still exceed E(θ) of their own frame
    (`exceedance`), the largest frame-to-frame jump of each leg joint raw vs corrected (m), the time per frame, and the
    invariant check (`check_invariants`).
    """
    c = correction
    poses = c.poses
    valid = poses.valid
    n_valid = int(valid.sum())
    rotated = c.rotated
    frames_corrected = int(rotated.any(axis=1).sum())
    into = np.isin(c.status, (K.ROTATED, K.CONSTRAINED))
    res = c.residual_m[into] if into.any() else np.zeros(1)
    short = np.isin(c.status, (K.CLOSEST, K.LIMITED, K.UNREACHABLE))
    res_short = c.residual_m[short] if short.any() else np.zeros(1)
    assert poses.raw_positions is not None
    jr = _max_jumps(poses.raw_positions, valid)
    jc = _max_jumps(poses.positions, valid)
    legs = [j for j in JOINTS if j.endswith(("knee", "ankle", "heel", "toe"))]
    return {
        "frames": int(poses.n_frames),
        "valid_frames": n_valid,
        "corrected_frames": frames_corrected,
        "fraction_corrected": round(frames_corrected / n_valid, 6) if n_valid else 0.0,
        "corrections": {name: int(rotated[:, i].sum()) for i, name in enumerate(PAIRS)},
        "status_counts": {
            name: {STATUS[int(s)]: int((c.status[:, i] == s).sum()) for s in np.unique(c.status[:, i])}
            for i, name in enumerate(PAIRS)
        },
        "residual_mm": {"max": round(float(res.max()) * 1e3, 6), "mean": round(float(res.mean()) * 1e3, 6)},
        "short_of_region": {
            "frames": int(short.any(axis=1).sum()),
            "max_mm": round(float(res_short.max()) * 1e3, 3),
            "mean_mm": round(float(res_short.mean()) * 1e3, 3),
        },
        "exceeds_own_limit": exceedance(poses),
        "max_jump_m": {
            j: {"raw": round(float(jr[INDEX[j]]), 6), "corrected": round(float(jc[INDEX[j]]), 6)} for j in legs
        },
        "max_jump_all_joints_m": {"raw": round(float(jr.max()), 6), "corrected": round(float(jc.max()), 6)},
        "time_per_frame_ms": round(c.seconds / max(1, poses.n_frames) * 1e3, 6),
        "constraints": poses.constraints.source if poses.constraints is not None else None,
        "invariants": check_invariants(c),
    }
