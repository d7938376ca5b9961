"""numba kernel of the posture correction (SPEC §5.3). The only entry point is `kitsuke.pose.correct_poses`,
which validates its inputs; `_reference.py` holds a plain-numpy version of the same algorithm for the tests.

Horizontal vectors are (x, z) pairs; "up" is +Y. An ellipse K is stored as six numbers
(cx, cz, ux, uz, a, b): centre, unit long-axis direction (left joint → right joint), semi-axes along û and along
v̂ = up × û = (uz, −ux).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

# status codes per frame and pair
INSIDE = 0  # pair inside K: frame untouched for this pair
ROTATED = 1  # target rotated into K'
ALREADY_INSIDE = 2  # pair outside K but both joints already inside K': nothing to rotate
CLOSEST = 3  # no angle reaches inside K': rotated to the closest angle
UNREACHABLE = 4  # no angle gets closer than the current pose (within the plausibility rules): not rotated
CONSTRAINED = 5  # rotated into K', by a larger angle than the smallest (which would swap sides or jump)
LIMITED = 6  # K' reachable only by swapping sides or jumping: rotated as near to K' as the rules allow
EASED = 7  # no correction needed, but dropping the previous one at once would jump: part of it kept
INVALID = -1  # no pose in this frame
#: Statuses where a segment was rotated.
ROTATING = (ROTATED, CLOSEST, CONSTRAINED, LIMITED, EASED)


@njit(cache=True)
def interp_periodic(theta: float, tt: np.ndarray, ee: np.ndarray) -> float:
    """E(θ): linear in the wrapped table (tt: radians with one wrapped entry on each side, ee: metres)."""
    th = theta % math.pi
    m = len(tt)
    for i in range(1, m):
        if th <= tt[i]:
            t0, t1 = tt[i - 1], tt[i]
            w = (th - t0) / (t1 - t0) if t1 > t0 else 0.0
            return ee[i - 1] + w * (ee[i] - ee[i - 1])
    return ee[m - 1]


@njit(cache=True)
def region(
    q: np.ndarray,
    jl: int,
    jr: int,
    hip_l: int,
    hip_r: int,
    tt: np.ndarray,
    ee: np.ndarray,
    area: float,
    out: np.ndarray,
) -> tuple[float, float]:
    """K of pose q (J, 3) for the pair (jl, jr) into out[6]; returns (horizontal distance d, E(θ))."""
    hx = q[hip_r, 0] - q[hip_l, 0]
    hz = q[hip_r, 2] - q[hip_l, 2]
    hn = math.sqrt(hx * hx + hz * hz)
    if hn < 1e-12:
        hx, hz = -1.0, 0.0  # no hip axis: assume the person faces +Z (left→right is −X)
    else:
        hx /= hn
        hz /= hn
    fx, fz = hz, -hx  # forward = up × hip axis
    ux = q[jr, 0] - q[jl, 0]
    uz = q[jr, 2] - q[jl, 2]
    d = math.sqrt(ux * ux + uz * uz)
    if d < 1e-12:
        ux, uz, theta = hx, hz, 0.0
    else:
        ux /= d
        uz /= d
        theta = math.atan2(ux * fx + uz * fz, ux * hx + uz * hz)
    e = interp_periodic(theta, tt, ee)
    a = 0.5 * e
    out[0] = 0.5 * (q[jl, 0] + q[jr, 0])
    out[1] = 0.5 * (q[jl, 2] + q[jr, 2])
    out[2] = ux
    out[3] = uz
    out[4] = a
    out[5] = area / (math.pi * a)
    return d, e


@njit(cache=True)
def inside_value(x: float, z: float, k: np.ndarray) -> float:
    """(ξ/a)² + (ζ/b)² − 1 of a horizontal point against ellipse k: ≤ 0 inside the vertical cylinder."""
    dx = x - k[0]
    dz = z - k[1]
    xi = dx * k[2] + dz * k[3]
    zeta = dx * k[3] - dz * k[2]
    return (xi / k[4]) ** 2 + (zeta / k[5]) ** 2 - 1.0


@njit(cache=True)
def closest_on_ellipse(a: float, b: float, px: float, pz: float) -> tuple[float, float]:
    """Closest point of the ellipse (ξ/a)² + (ζ/b)² = 1 to an outside point (px, pz), local coordinates.

    Eberly's method: the closest point is (a² y0/(t + a²), b² y1/(t + b²)) with t ≥ 0 the root of
    F(t) = (a y0/(t + a²))² + (b y1/(t + b²))² − 1, found by bisection on [0, max(a, b)·|p|] (F ≤ 0 there).
    """
    y0, y1 = abs(px), abs(pz)
    hi = max(a, b) * math.sqrt(y0 * y0 + y1 * y1)
    lo = 0.0
    a2, b2 = a * a, b * b
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        f = (a * y0 / (mid + a2)) ** 2 + (b * y1 / (mid + b2)) ** 2 - 1.0
        if f > 0.0:
            lo = mid
        else:
            hi = mid
        if hi - lo <= 1e-15 * (1.0 + hi):
            break
    t = 0.5 * (lo + hi)
    x0 = a2 * y0 / (t + a2)
    x1 = b2 * y1 / (t + b2)
    return math.copysign(x0, px), math.copysign(x1, pz)


@njit(cache=True)
def outside_distance(x: float, z: float, k: np.ndarray) -> float:
    """Horizontal distance of a point outside ellipse k to it, metres (0 inside)."""
    if inside_value(x, z, k) <= 0.0:
        return 0.0
    dx = x - k[0]
    dz = z - k[1]
    xi = dx * k[2] + dz * k[3]
    zeta = dx * k[3] - dz * k[2]
    cx, cz = closest_on_ellipse(k[4], k[5], xi, zeta)
    return math.sqrt((cx - xi) ** 2 + (cz - zeta) ** 2)


@njit(cache=True)
def rotate(v: np.ndarray, e: np.ndarray, c: float, s: float, out: np.ndarray) -> None:
    """Rodrigues: out = v rotated about the unit axis e by the angle with cosine c and sine s."""
    ex, ey, ez = e[0], e[1], e[2]
    dot = ex * v[0] + ey * v[1] + ez * v[2]
    cx = ey * v[2] - ez * v[1]
    cy = ez * v[0] - ex * v[2]
    cz = ex * v[1] - ey * v[0]
    out[0] = v[0] * c + cx * s + ex * dot * (1.0 - c)
    out[1] = v[1] * c + cy * s + ey * dot * (1.0 - c)
    out[2] = v[2] * c + cz * s + ez * dot * (1.0 - c)


@njit(cache=True)
def _target_at(
    q: np.ndarray, start: int, target: int, e: np.ndarray, alpha: float, tmp: np.ndarray, out: np.ndarray
) -> None:
    for c in range(3):
        tmp[c] = q[target, c] - q[start, c]
    rotate(tmp, e, math.cos(alpha), math.sin(alpha), out)
    for c in range(3):
        out[c] += q[start, c]


@njit(cache=True)
def violation(
    q: np.ndarray,
    raw_f: np.ndarray,
    raw_prev: np.ndarray,
    out_prev: np.ndarray,
    has_prev: bool,
    moved_row: np.ndarray,
    sj: int,
    e: np.ndarray,
    alpha: float,
    rules: np.ndarray,
    tmp: np.ndarray,
    pt: np.ndarray,
) -> tuple[bool, float]:
    """How far rotating the segment at `sj` (and the joints `moved_row` with it) by `alpha` about `e` breaks the
    plausibility rules. `rules` = (px, pz, nx, nz, max_jump, margin, n_jump): the sagittal plane through (px, pz)
    with horizontal normal (nx, nz), metres; the jump allowance and the side margin, metres; how many of the moved
    joints (from the target down) have their jump checked.

    Returns (a moved joint ends more than `margin` on the other side of the plane than its raw position; the
    largest frame-to-frame move of a checked joint beyond its raw move plus `max_jump`, metres: ≤ 0 within, -inf
    without a previous frame). The knee pass checks the knee's jump only: the ankle pass that follows can still
    rotate the shin back, and checks the ankle, heel and toe.
    """
    px, pz, nx, nz, max_jump, margin = rules[0], rules[1], rules[2], rules[3], rules[4], rules[5]
    n_jump = int(rules[6])
    c, s = math.cos(alpha), math.sin(alpha)
    crosses = False
    excess = -np.inf
    for i in range(moved_row.shape[0]):
        m = moved_row[i]
        if m < 0:
            break
        for k in range(3):
            tmp[k] = q[m, k] - q[sj, k]
        rotate(tmp, e, c, s, pt)
        for k in range(3):
            pt[k] += q[sj, k]
        side_raw = (raw_f[m, 0] - px) * nx + (raw_f[m, 2] - pz) * nz
        side_now = (pt[0] - px) * nx + (pt[2] - pz) * nz
        if side_raw * side_now < 0.0 and abs(side_now) > margin:
            crosses = True
        if has_prev and i < n_jump:
            dc = math.sqrt(
                (pt[0] - out_prev[m, 0]) ** 2 + (pt[1] - out_prev[m, 1]) ** 2 + (pt[2] - out_prev[m, 2]) ** 2
            )
            dr = math.sqrt(
                (raw_f[m, 0] - raw_prev[m, 0]) ** 2
                + (raw_f[m, 1] - raw_prev[m, 1]) ** 2
                + (raw_f[m, 2] - raw_prev[m, 2]) ** 2
            )
            excess = max(excess, dc - dr - max_jump)
    return crosses, excess


@njit(cache=True)
def ease(
    q: np.ndarray,
    raw_f: np.ndarray,
    raw_prev: np.ndarray,
    out_prev: np.ndarray,
    moved_row: np.ndarray,
    sj: int,
    e: np.ndarray,
    alpha_prev: float,
    rules: np.ndarray,
    tmp: np.ndarray,
    pt: np.ndarray,
) -> float:
    """The part of the previous frame's rotation (`alpha_prev` about `e`) to keep in a frame that needs none, so
    that no moved joint jumps more than its raw motion plus `max_jump`: 0 when dropping it all is within the rule,
    else the smallest fraction that is (sampled in 1/16ths, then bisected), or the fraction that jumps least."""
    cr, ex = violation(q, raw_f, raw_prev, out_prev, True, moved_row, sj, e, 0.0, rules, tmp, pt)
    if not cr and ex <= 0.0:
        return 0.0
    least, least_ex = 0.0, ex if not cr else np.inf
    for k in range(1, 17):
        lam = k / 16.0
        cr, ex = violation(
            q,
            raw_f,
            raw_prev,
            out_prev,
            True,
            moved_row,
            sj,
            e,
            lam * alpha_prev,
            rules,
            tmp,
            pt,
        )
        if cr:
            continue
        if ex <= 0.0:
            lo, hi = (k - 1) / 16.0, lam
            for _ in range(20):
                mid = 0.5 * (lo + hi)
                cr, ex = violation(
                    q,
                    raw_f,
                    raw_prev,
                    out_prev,
                    True,
                    moved_row,
                    sj,
                    e,
                    mid * alpha_prev,
                    rules,
                    tmp,
                    pt,
                )
                if not cr and ex <= 0.0:
                    hi = mid
                else:
                    lo = mid
            return hi * alpha_prev
        if ex < least_ex:
            least, least_ex = lam, ex
    return least * alpha_prev


@njit(cache=True)
def apply_rotation(q: np.ndarray, moved_row: np.ndarray, sj: int, e: np.ndarray, alpha: float, tmp, pt) -> None:
    """Rotate the joints `moved_row` (-1 padded) of pose q about the axis e through joint sj by alpha, in place."""
    cb, sb = math.cos(alpha), math.sin(alpha)
    for i in range(moved_row.shape[0]):
        m = moved_row[i]
        if m < 0:
            break
        for c in range(3):
            tmp[c] = q[m, c] - q[sj, c]
        rotate(tmp, e, cb, sb, pt)
        for c in range(3):
            q[m, c] = q[sj, c] + pt[c]


@njit(cache=True)
def toward_previous(q: np.ndarray, out_prev: np.ndarray, sj: int, tj: int, e: np.ndarray) -> float:
    """The rotation about the segment's start sj that turns this frame's segment sj -> tj onto the previous
    corrected frame's direction: its unit axis into e, its angle returned (0 when already along it)."""
    ax, ay, az = q[tj, 0] - q[sj, 0], q[tj, 1] - q[sj, 1], q[tj, 2] - q[sj, 2]
    bx, by, bz = out_prev[tj, 0] - out_prev[sj, 0], out_prev[tj, 1] - out_prev[sj, 1], out_prev[tj, 2] - out_prev[sj, 2]
    cx, cy, cz = ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx
    cn = math.sqrt(cx * cx + cy * cy + cz * cz)
    if cn < 1e-12:
        return 0.0
    e[0], e[1], e[2] = cx / cn, cy / cn, cz / cn
    return math.atan2(cn, ax * bx + ay * by + az * bz)


@njit(cache=True)
def _ease_pair(
    q, positions, out, f, p, target, angle, axes, status, start_joints, moved, pair_joints, rules, tmp, pt, e, skip,
) -> None:  # fmt: skip
    """Frame f rotates nothing for pair p: where a chain (either leg) would then jump past the rule — the previous
    frame rotated it, or this frame's knee pass moved the shin — turn its segment toward the previous frame's
    direction by the smallest part that keeps the rule (`ease`), recording it as EASED. `skip`: a side this frame
    has rotated already (its rotation is what is recorded; -1 for none)."""
    for side in range(2):
        if side == skip:
            continue
        sj = start_joints[p, side]
        tj = pair_joints[p, side]
        cr, ex = violation(
            q, positions[f], positions[f - 1], out[f - 1], True, moved[p, side], sj, e, 0.0, rules, tmp, pt
        )
        if ex <= 0.0:
            continue
        full = toward_previous(q, out[f - 1], sj, tj, e)
        if full <= 0.0:
            continue
        alpha = ease(q, positions[f], positions[f - 1], out[f - 1], moved[p, side], sj, e, full, rules, tmp, pt)
        if alpha > 0.0:
            apply_rotation(q, moved[p, side], sj, e, alpha, tmp, pt)
            if skip >= 0:
                continue
            status[f, p] = EASED
            target[f, p] = tj
            angle[f, p] = alpha
            for c in range(3):
                axes[f, p, c] = e[c]


@njit(cache=True)
def correct_frames(
    positions: np.ndarray,  # (n, J, 3) input, read only
    valid: np.ndarray,  # (n,) bool
    tt: np.ndarray,  # (2, m+2) wrapped θ tables, radians
    ee: np.ndarray,  # (2, m+2) E tables, metres
    area: np.ndarray,  # (2,) m²
    pair_joints: np.ndarray,  # (2, 2): [pair][left, right]
    start_joints: np.ndarray,  # (2, 2): segment start per [pair][side]
    moved: np.ndarray,  # (2, 2, 4): joints rotating with the segment per [pair][side], -1 padded
    hip_l: int,
    hip_r: int,
    pelvis: int,
    tol: float,
    n_samples: int,
    max_jump: float,  # m: a moved joint may move at most its raw move plus this between frames
    margin: float,  # m: a moved joint may end this far on the other side of the sagittal plane than its raw place
    out: np.ndarray,  # (n, J, 3) = copy of positions on entry; corrected in place
    target: np.ndarray,  # (n, 2) int64 out: target joint or -1
    angle: np.ndarray,  # (n, 2) out: rotation angle, radians
    residual: np.ndarray,  # (n, 2) out: target's distance outside K' after correction, metres
    regions: np.ndarray,  # (n, 2, 6) out: K' used
    status: np.ndarray,  # (n, 2) int8 out
    stage_input: np.ndarray,  # (n, 2, 3) out: the target's position when its pass started (before rotation)
    axes: np.ndarray,  # (n, 2, 3) out: the rotation axis, where a segment was rotated
    start: int,  # first frame to correct; rows before it hold earlier results (online use: one frame at a time)
) -> None:
    n = positions.shape[0]
    k_now = np.empty(6)
    k_prev = np.empty(6)
    e = np.empty(3)
    tmp = np.empty(3)
    pt = np.empty(3)
    tmp2 = np.empty(3)
    pt2 = np.empty(3)
    rules = np.array([0.0, 0.0, 1.0, 0.0, max_jump, margin, 1.0])
    e2 = np.empty(3)
    prev_valid = start > 0 and valid[start - 1]
    for f in range(start, n):
        if not valid[f]:
            prev_valid = False
            for p in range(2):
                status[f, p] = INVALID
                target[f, p] = -1
            continue
        q = out[f]
        # the sagittal plane (through the pelvis, normal along the hip axis; neither moves in a correction)
        nx = q[hip_l, 0] - q[hip_r, 0]
        nz = q[hip_l, 2] - q[hip_r, 2]
        nn = max(math.sqrt(nx * nx + nz * nz), 1e-12)
        rules[0], rules[1], rules[2], rules[3] = q[pelvis, 0], q[pelvis, 2], nx / nn, nz / nn
        prev_f = f - 1 if prev_valid else f
        for p in range(2):
            rules[6] = 1.0 if p == 0 else moved.shape[2]
            jl = pair_joints[p, 0]
            jr = pair_joints[p, 1]
            target[f, p] = -1
            angle[f, p] = 0.0
            residual[f, p] = 0.0
            d, lim = region(q, jl, jr, hip_l, hip_r, tt[p], ee[p], area[p], k_now)
            # where this frame rotates nothing, the previous frame's rotation of this pair, if any, is eased out
            if not d > lim:
                status[f, p] = INSIDE
                if prev_valid:
                    _ease_pair(
                        q, positions, out, f, p, target, angle, axes, status, start_joints, moved, pair_joints, rules,
                        tmp2, pt2, e2, -1,
                    )  # fmt: skip
                continue
            if prev_valid:
                region(out[f - 1], jl, jr, hip_l, hip_r, tt[p], ee[p], area[p], k_prev)
            else:
                for c in range(6):
                    k_prev[c] = k_now[c]
            for c in range(6):
                regions[f, p, c] = k_prev[c]
            # target: the joint of the pair farther (horizontally) from the pelvis; if that one is already inside K'
            # and the other is not, the other (rotating a joint inside K' would leave the pair apart: a visible spike)
            dl = (q[jl, 0] - q[pelvis, 0]) ** 2 + (q[jl, 2] - q[pelvis, 2]) ** 2
            dr = (q[jr, 0] - q[pelvis, 0]) ** 2 + (q[jr, 2] - q[pelvis, 2]) ** 2
            side = 0 if dl >= dr else 1
            # the leg rotated in the previous frame stays the target: switching legs would snap the other one
            # back to its raw place in one frame (a jump of the whole correction)
            if prev_valid and target[f - 1, p] >= 0 and angle[f - 1, p] > 0.0:
                side = 0 if target[f - 1, p] == jl else 1
            if inside_value(q[pair_joints[p, side], 0], q[pair_joints[p, side], 2], k_prev) <= 0.0:
                other = 1 - side
                if inside_value(q[pair_joints[p, other], 0], q[pair_joints[p, other], 2], k_prev) > 0.0:
                    side = other
            tj = pair_joints[p, side]
            sj = start_joints[p, side]
            target[f, p] = tj
            for c in range(3):
                stage_input[f, p, c] = q[tj, c]
            x, z = q[tj, 0], q[tj, 2]
            if inside_value(x, z, k_prev) <= 0.0:
                status[f, p] = ALREADY_INSIDE
                if prev_valid:
                    _ease_pair(
                        q, positions, out, f, p, target, angle, axes, status, start_joints, moved, pair_joints, rules,
                        tmp2, pt2, e2, -1,
                    )  # fmt: skip
                continue
            # w: horizontal direction from the target toward its closest point on the ellipse of K'
            dx, dz = x - k_prev[0], z - k_prev[1]
            xi = dx * k_prev[2] + dz * k_prev[3]
            zeta = dx * k_prev[3] - dz * k_prev[2]
            cxi, czeta = closest_on_ellipse(k_prev[4], k_prev[5], xi, zeta)
            wl0, wl1 = cxi - xi, czeta - zeta
            wn = math.sqrt(wl0 * wl0 + wl1 * wl1)
            wl0 /= wn
            wl1 /= wn
            wx = wl0 * k_prev[2] + wl1 * k_prev[3]  # back to world: ξ along û, ζ along v̂ = (uz, −ux)
            wz = wl0 * k_prev[3] - wl1 * k_prev[2]
            # rotation axis e = normalise(segment × w); if the two are parallel, e = up × w
            sx = q[tj, 0] - q[sj, 0]
            sy = q[tj, 1] - q[sj, 1]
            sz = q[tj, 2] - q[sj, 2]
            slen = math.sqrt(sx * sx + sy * sy + sz * sz)
            e[0] = sy * wz
            e[1] = sz * wx - sx * wz
            e[2] = -sy * wx
            en = math.sqrt(e[0] ** 2 + e[1] ** 2 + e[2] ** 2)
            if en < 1e-9 * max(slen, 1e-12):
                e[0], e[1], e[2] = wz, 0.0, -wx  # up × w
                en = 1.0
            for c in range(3):
                e[c] /= en
            row = moved[p, side]
            # smallest angle that brings the target inside and keeps the rules: bracket by sampling (0, π], then
            # bisect on (inside and allowed)
            step = math.pi / n_samples
            found = -1
            any_inside = False
            for k in range(1, n_samples + 1):
                _target_at(q, sj, tj, e, k * step, tmp, pt)
                if inside_value(pt[0], pt[2], k_prev) <= 0.0:
                    cr, ex = violation(
                        q,
                        positions[f],
                        positions[prev_f],
                        out[prev_f],
                        prev_valid,
                        row,
                        sj,
                        e,
                        k * step,
                        rules,
                        tmp2,
                        pt2,
                    )
                    if not cr and ex <= 0.0:
                        found = k
                        break
                    any_inside = True
            if found > 0:
                lo, hi = (found - 1) * step, found * step
                while (hi - lo) * slen > tol:
                    mid = 0.5 * (lo + hi)
                    _target_at(q, sj, tj, e, mid, tmp, pt)
                    ok = inside_value(pt[0], pt[2], k_prev) <= 0.0
                    if ok:
                        cr, ex = violation(
                            q,
                            positions[f],
                            positions[prev_f],
                            out[prev_f],
                            prev_valid,
                            row,
                            sj,
                            e,
                            mid,
                            rules,
                            tmp2,
                            pt2,
                        )
                        ok = not cr and ex <= 0.0
                    if ok:
                        hi = mid
                    else:
                        lo = mid
                best = hi
                status[f, p] = CONSTRAINED if any_inside else ROTATED
            else:
                # no allowed angle reaches inside: the allowed sampled angle that comes closest, refined by golden
                # section (a refined angle is kept only if allowed); with none allowed (the previous frame's
                # correction is already too far from this frame's raw pose), the one that jumps least
                best, best_d = 0.0, outside_distance(x, z, k_prev)
                cr, ex = violation(
                    q,
                    positions[f],
                    positions[prev_f],
                    out[prev_f],
                    prev_valid,
                    row,
                    sj,
                    e,
                    0.0,
                    rules,
                    tmp2,
                    pt2,
                )
                allowed0 = not cr and ex <= 0.0
                least_ex, least_k = ex if not cr else np.inf, 0
                kbest = 0 if allowed0 else -1
                for k in range(1, n_samples + 1):
                    cr, ex = violation(
                        q,
                        positions[f],
                        positions[prev_f],
                        out[prev_f],
                        prev_valid,
                        row,
                        sj,
                        e,
                        k * step,
                        rules,
                        tmp2,
                        pt2,
                    )
                    if cr:
                        continue
                    if ex < least_ex:
                        least_ex, least_k = ex, k
                    if ex > 0.0:
                        continue
                    _target_at(q, sj, tj, e, k * step, tmp, pt)
                    dd = outside_distance(pt[0], pt[2], k_prev)
                    if kbest < 0 or dd < best_d:
                        best, best_d, kbest = k * step, dd, k
                if kbest < 0:
                    best = least_k * step
                    # no angle about this frame's axis keeps near the previous correction: keep (part of) the
                    # previous frame's rotation about its own axis instead when that jumps less
                    if prev_valid:
                        full = toward_previous(q, out[f - 1], sj, tj, e2)
                        lam_alpha = ease(
                            q, positions[f], positions[f - 1], out[f - 1], row, sj, e2, full, rules, tmp2, pt2
                        )
                        cr, ex = violation(
                            q, positions[f], positions[f - 1], out[f - 1], True, row, sj, e2, lam_alpha, rules,
                            tmp2, pt2,
                        )  # fmt: skip
                        if not cr and ex < least_ex and lam_alpha > 0.0:
                            for c in range(3):
                                e[c] = e2[c]
                            best = lam_alpha
                    _target_at(q, sj, tj, e, best, tmp, pt)
                    best_d = outside_distance(pt[0], pt[2], k_prev)
                elif kbest > 0:
                    lo = max(0.0, (kbest - 1) * step)
                    hi = min(math.pi, (kbest + 1) * step)
                    g = 0.5 * (math.sqrt(5.0) - 1.0)
                    while (hi - lo) * slen > tol:
                        m1 = hi - g * (hi - lo)
                        m2 = lo + g * (hi - lo)
                        _target_at(q, sj, tj, e, m1, tmp, pt)
                        d1 = outside_distance(pt[0], pt[2], k_prev)
                        _target_at(q, sj, tj, e, m2, tmp, pt)
                        d2 = outside_distance(pt[0], pt[2], k_prev)
                        if d1 < d2:
                            hi = m2
                        else:
                            lo = m1
                    mid = 0.5 * (lo + hi)
                    _target_at(q, sj, tj, e, mid, tmp, pt)
                    dmid = outside_distance(pt[0], pt[2], k_prev)
                    cr, ex = violation(
                        q,
                        positions[f],
                        positions[prev_f],
                        out[prev_f],
                        prev_valid,
                        row,
                        sj,
                        e,
                        mid,
                        rules,
                        tmp2,
                        pt2,
                    )
                    if dmid < best_d and not cr and ex <= 0.0:
                        best, best_d = mid, dmid
                if best == 0.0:
                    status[f, p] = UNREACHABLE
                    residual[f, p] = best_d
                    if prev_valid:
                        _ease_pair(
                            q, positions, out, f, p, target, angle, axes, status, start_joints, moved, pair_joints,
                            rules, tmp2, pt2, e2, -1,
                        )  # fmt: skip
                    continue
                status[f, p] = LIMITED if (any_inside or kbest < 0) else CLOSEST
            # rotate the segment and everything below it about the axis through the start joint
            apply_rotation(q, row, sj, e, best, tmp, pt)
            angle[f, p] = best
            for c in range(3):
                axes[f, p, c] = e[c]
            residual[f, p] = outside_distance(q[tj, 0], q[tj, 2], k_prev)
            if prev_valid:  # the other leg, if rotated in the previous frame, must not snap back either
                _ease_pair(
                    q, positions, out, f, p, target, angle, axes, status, start_joints, moved, pair_joints, rules,
                    tmp2, pt2, e2, side,
                )  # fmt: skip
        prev_valid = True
