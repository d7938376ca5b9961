"""Plain-Python versions of the dynamic solver's kernels (`_dynamics_kernels.py`), written from the formulas for the
tests: XPBD's multiplier update, the strain limit, a tapered capsule's closest point, Coulomb friction. Slow; not
used by the library. Each returns new arrays instead of working in place."""

from __future__ import annotations

import numpy as np


def predict(x, v, inv_mass, gravity, h):
    v = v.copy()
    free = inv_mass > 0
    v[free, 1] -= gravity * h
    p = x.copy()
    p[free] = x[free] + h * v[free]
    return p, v


def solve_distances(p, inv_mass, pairs, rest, alpha, alpha_short, lam):
    p, lam = p.copy(), lam.copy()
    for k, (a, b) in enumerate(pairs):
        w = inv_mass[a] + inv_mass[b]
        diff = p[a] - p[b]
        d = np.linalg.norm(diff)
        if w == 0 or d < 1e-12:
            continue
        al = alpha if d > rest[k] else alpha_short
        dl = (-(d - rest[k]) - al * lam[k]) / (w + al)  # Macklin et al. 2016, eq. 18
        lam[k] += dl
        n = diff / d
        p[a] = p[a] + inv_mass[a] * dl * n
        p[b] = p[b] - inv_mass[b] * dl * n
    return p, lam


def limit_strain(p, inv_mass, pairs, rest, max_strain, max_squeeze):
    p = p.copy()
    for k, (a, b) in enumerate(pairs):
        w = inv_mass[a] + inv_mass[b]
        diff = p[a] - p[b]
        d = np.linalg.norm(diff)
        top, bottom = (1 + max_strain) * rest[k], (1 - max_squeeze) * rest[k]
        if w == 0 or bottom <= d <= top or d < 1e-12:
            continue
        corr = (d - (top if d > top else bottom)) / w * diff / d
        p[a] = p[a] - inv_mass[a] * corr
        p[b] = p[b] + inv_mass[b] * corr
    return p


def collide_capsules(p, x, inv_mass, ends, radii, moved, offset, friction):
    p = p.copy()
    for i in range(len(p)):
        if inv_mass[i] == 0:
            continue
        for k in range(len(ends)):
            a, u = ends[k, 0], ends[k, 1] - ends[k, 0]
            t = float(np.clip((p[i] - a) @ u / (u @ u), 0, 1)) if u @ u > 0 else 0.0
            c = a + t * u
            r = radii[k, 0] + t * (radii[k, 1] - radii[k, 0]) + offset
            off = p[i] - c
            d = np.linalg.norm(off)
            if d >= r or d < 1e-12:
                continue
            n = off / d
            depth = r - d
            p[i] = p[i] + depth * n
            rel = p[i] - x[i] - ((1 - t) * moved[k, 0] + t * moved[k, 1])
            tangent = rel - (rel @ n) * n
            tl = np.linalg.norm(tangent)
            if tl > 0:
                p[i] = p[i] - min(1.0, friction * depth / tl) * tangent
    return p
