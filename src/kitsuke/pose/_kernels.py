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
UNREACHABLE = 4  # no angle gets closer than the current pose: not rotated
INVALID = -1  # no pose in this frame


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
    out: np.ndarray,  # (n, J, 3) = copy of positions on entry; corrected in place
    target: np.ndarray,  # (n, 2) int64 out: target joint or -1
    angle: np.ndarray,  # (n, 2) out: rotation angle, radians
    residual: np.ndarray,  # (n, 2) out: target's distance outside K' after correction, metres
    regions: np.ndarray,  # (n, 2, 6) out: K' used
    status: np.ndarray,  # (n, 2) int8 out
    stage_input: np.ndarray,  # (n, 2, 3) out: the target's position when its pass started (before rotation)
) -> None:
    n = positions.shape[0]
    k_now = np.empty(6)
    k_prev = np.empty(6)
    e = np.empty(3)
    tmp = np.empty(3)
    pt = np.empty(3)
    prev_valid = False
    for f in range(n):
        if not valid[f]:
            prev_valid = False
            for p in range(2):
                status[f, p] = INVALID
                target[f, p] = -1
            continue
        q = out[f]
        for p in range(2):
            jl = pair_joints[p, 0]
            jr = pair_joints[p, 1]
            target[f, p] = -1
            angle[f, p] = 0.0
            residual[f, p] = 0.0
            d, lim = region(q, jl, jr, hip_l, hip_r, tt[p], ee[p], area[p], k_now)
            if not d > lim:
                status[f, p] = INSIDE
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
            # smallest angle bringing the target inside: bracket by sampling (0, π], then bisect
            step = math.pi / n_samples
            found = -1
            for k in range(1, n_samples + 1):
                _target_at(q, sj, tj, e, k * step, tmp, pt)
                if inside_value(pt[0], pt[2], k_prev) <= 0.0:
                    found = k
                    break
            if found > 0:
                lo, hi = (found - 1) * step, found * step
                while (hi - lo) * slen > tol:
                    mid = 0.5 * (lo + hi)
                    _target_at(q, sj, tj, e, mid, tmp, pt)
                    if inside_value(pt[0], pt[2], k_prev) <= 0.0:
                        hi = mid
                    else:
                        lo = mid
                best = hi
                status[f, p] = ROTATED
            else:
                # no angle reaches inside: the sampled angle that comes closest, refined by golden section
                best, best_d = 0.0, outside_distance(x, z, k_prev)
                kbest = 0
                for k in range(1, n_samples + 1):
                    _target_at(q, sj, tj, e, k * step, tmp, pt)
                    dd = outside_distance(pt[0], pt[2], k_prev)
                    if dd < best_d:
                        best, best_d, kbest = k * step, dd, k
                if kbest == 0:
                    status[f, p] = UNREACHABLE
                    residual[f, p] = best_d
                    continue
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
                if outside_distance(pt[0], pt[2], k_prev) < best_d:
                    best = mid
                status[f, p] = CLOSEST
            # rotate the segment and everything below it about the axis through the start joint
            cb, sb = math.cos(best), math.sin(best)
            for i in range(moved.shape[2]):
                m = moved[p, side, i]
                if m < 0:
                    break
                for c in range(3):
                    tmp[c] = q[m, c] - q[sj, c]
                rotate(tmp, e, cb, sb, pt)
                for c in range(3):
                    q[m, c] = q[sj, c] + pt[c]
            angle[f, p] = best
            residual[f, p] = outside_distance(q[tj, 0], q[tj, 2], k_prev)
        prev_valid = True
