"""Plain-numpy reference of the posture correction (SPEC §5.3), written independently of `_kernels.py` for the
tests: vectorised angle sampling, scipy rotations, closest ellipse point by dense sampling refined with a bounded
scalar minimisation. Slow (milliseconds per frame); not used by the library. It is the SPEC's rotation with the
kernel's choice of target (the leg rotated in the previous frame stays the target) but without the plausibility
rules: compare with `correct_poses(..., max_jump_m=inf, side_margin_m=inf)`."""

from __future__ import annotations

import numpy as np
from scipy.optimize import minimize_scalar
from scipy.spatial.transform import Rotation

from ..skeleton import INDEX
from ._constraints import PAIRS, ConstraintTable
from ._correct import MOVED, PAIR_JOINTS, START_JOINTS, inside_values, regions_of


def _closest_point(ell: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Closest point (x, z) on the boundary of ellipse ell (6,) to the horizontal point x (2,)."""
    c, u, a, b = ell[:2], ell[2:4], ell[4], ell[5]
    v = np.array([u[1], -u[0]])

    def point(t: float) -> np.ndarray:
        return c + a * np.cos(t) * u + b * np.sin(t) * v

    ts = np.linspace(0, 2 * np.pi, 4096, endpoint=False)
    pts = c + a * np.cos(ts)[:, None] * u + b * np.sin(ts)[:, None] * v
    t0 = ts[np.argmin(np.linalg.norm(pts - x, axis=1))]
    h = 2 * np.pi / 4096
    r = minimize_scalar(
        lambda t: float(np.sum((point(t) - x) ** 2)),
        bounds=(t0 - h, t0 + h),
        method="bounded",
        options={"xatol": 1e-13},
    )
    return point(r.x)


def _outside_distance(ell: np.ndarray, x: np.ndarray) -> float:
    if inside_values(x[None], ell[None])[0] <= 0:
        return 0.0
    return float(np.linalg.norm(_closest_point(ell, x) - x))


def correct_reference(
    positions: np.ndarray,
    valid: np.ndarray,
    constraints: ConstraintTable,
    *,
    tolerance_m: float = 1e-4,
    samples: int = 64,
) -> tuple[np.ndarray, np.ndarray]:
    """Corrected positions (n, J, 3) and targets (n, 2) (-1 where no segment was rotated)."""
    out = np.array(positions, dtype=np.float64, copy=True)
    n = len(out)
    targets = -np.ones((n, 2), dtype=np.int64)
    up = np.array([0.0, 1.0, 0.0])
    for f in range(n):
        if not valid[f]:
            continue
        for pi, name in enumerate(PAIRS):
            q = out[f]
            _, excess = regions_of(q[None], constraints, name)
            if not excess[0] > 0:
                continue
            jl, jr = PAIR_JOINTS[pi]
            pel = q[INDEX["pelvis"], ::2]
            side = 0 if np.sum((q[jl, ::2] - pel) ** 2) >= np.sum((q[jr, ::2] - pel) ** 2) else 1
            if f > 0 and valid[f - 1] and targets[f - 1, pi] >= 0:  # the leg rotated last frame stays the target
                side = 0 if targets[f - 1, pi] == jl else 1
            prev = out[f - 1] if f > 0 and valid[f - 1] else q
            ell = regions_of(prev[None], constraints, name)[0][0]
            ins = inside_values(q[PAIR_JOINTS[pi], ::2], np.broadcast_to(ell, (2, 6)))
            if ins[side] <= 0 < ins[1 - side]:  # the farther joint is inside K', the other is not: take the other
                side = 1 - side
            tj, sj = PAIR_JOINTS[pi, side], START_JOINTS[pi, side]
            x = q[tj, ::2]
            if inside_values(x[None], ell[None])[0] <= 0:
                continue
            w2 = _closest_point(ell, x) - x
            w = np.array([w2[0], 0.0, w2[1]]) / np.linalg.norm(w2)
            s = q[tj] - q[sj]
            e = np.cross(s, w)
            if np.linalg.norm(e) < 1e-9 * max(np.linalg.norm(s), 1e-12):
                e = np.cross(up, w)
            e /= np.linalg.norm(e)

            def rotated(alpha: np.ndarray, e: np.ndarray = e, s: np.ndarray = s, q: np.ndarray = q, sj: int = sj):
                return q[sj] + Rotation.from_rotvec(np.outer(np.atleast_1d(alpha), e)).apply(s)

            alphas = np.arange(1, samples + 1) * (np.pi / samples)
            g = inside_values(rotated(alphas)[:, ::2], np.broadcast_to(ell, (samples, 6)))
            inside = np.flatnonzero(g <= 0)
            slen = np.linalg.norm(s)
            if len(inside):
                k = inside[0] + 1
                lo, hi = (k - 1) * np.pi / samples, k * np.pi / samples
                while (hi - lo) * slen > tolerance_m:
                    mid = 0.5 * (lo + hi)
                    if inside_values(rotated(mid)[:, ::2], ell[None])[0] <= 0:
                        hi = mid
                    else:
                        lo = mid
                best = hi
            else:
                d0 = _outside_distance(ell, x)
                ds = np.array([_outside_distance(ell, p[::2]) for p in rotated(alphas)])
                if ds.min() >= d0:
                    continue
                k = int(np.argmin(ds)) + 1
                r = minimize_scalar(
                    lambda a, ell=ell: _outside_distance(ell, rotated(a)[0, ::2]),
                    bounds=(max(0.0, (k - 1) * np.pi / samples), min(np.pi, (k + 1) * np.pi / samples)),
                    method="bounded",
                    options={"xatol": tolerance_m / slen},
                )
                best = r.x if r.fun < ds[k - 1] else alphas[k - 1]
            rot = Rotation.from_rotvec(best * e)
            moved = [m for m in MOVED[pi, side] if m >= 0]
            q[moved] = q[sj] + rot.apply(q[moved] - q[sj])
            targets[f, pi] = tj
    return out, targets
