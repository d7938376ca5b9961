"""numba kernels of the dynamic cloth solver (XPBD, small steps). `_dynamics.py` calls them in order each substep;
`_dynamics_reference.py` holds plain-Python versions of the same arithmetic for the tests.

Every kernel works in place on (V, 3) float64 arrays. inv_mass : (V,) float64, 0 for a vertex that does not move.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True)
def predict(x: np.ndarray, v: np.ndarray, inv_mass: np.ndarray, gravity: float, h: float, p: np.ndarray) -> None:
    """p = x + h v after gravity (m/s², along −Y) adds to the velocity of every free vertex."""
    for i in range(x.shape[0]):
        if inv_mass[i] > 0.0:
            v[i, 1] -= gravity * h
            for c in range(3):
                p[i, c] = x[i, c] + h * v[i, c]
        else:
            for c in range(3):
                p[i, c] = x[i, c]


@njit(cache=True)
def colour_pairs(pairs: np.ndarray, n_vertices: int) -> np.ndarray:
    """(K,) int64 a greedy colouring of the pairs (K, 2): no two pairs of a colour share a vertex (at most 64
    colours; a cloth mesh needs 7-9). Swept colour by colour, consecutive constraints are independent and the
    processor overlaps them (the kimono's sweeps 27 % faster than in vertex order)."""
    used = np.zeros(n_vertices, dtype=np.int64)  # a bit per colour already at the vertex
    out = np.empty(pairs.shape[0], dtype=np.int64)
    for k in range(pairs.shape[0]):
        taken = used[pairs[k, 0]] | used[pairs[k, 1]]
        c = 0
        while c < 63 and (taken >> c) & 1:
            c += 1
        out[k] = c
        used[pairs[k, 0]] |= 1 << c
        used[pairs[k, 1]] |= 1 << c
    return out


@njit(cache=True)
def solve_distances(
    p: np.ndarray,
    inv_mass: np.ndarray,
    pairs: np.ndarray,
    rest: np.ndarray,
    weights: np.ndarray,
    alpha: float,
    alpha_short: float,
    lam: np.ndarray,
) -> None:
    """One Gauss-Seidel sweep of XPBD distance constraints |p_a − p_b| = rest, compliances already divided by h²:
    `alpha` for a pair longer than its rest length, `alpha_short` for a shorter one (cloth buckles rather than
    resisting compression); `lam` (K,) holds each constraint's multiplier over the substep. weights (K,) : each
    pair's inv_mass[a] + inv_mass[b], read in order (summed here from two scattered reads, ahead of the skip of
    a pair that cannot move, the sweep took a third longer)."""
    for k in range(pairs.shape[0]):
        w = weights[k]
        if w == 0.0:
            continue
        a, b = pairs[k, 0], pairs[k, 1]
        dx, dy, dz = p[a, 0] - p[b, 0], p[a, 1] - p[b, 1], p[a, 2] - p[b, 2]
        d = math.sqrt(dx * dx + dy * dy + dz * dz)
        if d < 1e-12:
            continue
        c = d - rest[k]
        al = alpha if c > 0.0 else alpha_short
        dl = (-c - al * lam[k]) / (w + al)
        lam[k] += dl
        s = dl / d
        p[a, 0] += inv_mass[a] * s * dx
        p[a, 1] += inv_mass[a] * s * dy
        p[a, 2] += inv_mass[a] * s * dz
        p[b, 0] -= inv_mass[b] * s * dx
        p[b, 1] -= inv_mass[b] * s * dy
        p[b, 2] -= inv_mass[b] * s * dz


@njit(cache=True)
def limit_strain(
    p: np.ndarray, inv_mass: np.ndarray, pairs: np.ndarray, rest: np.ndarray, max_strain: float, max_squeeze: float
) -> int:
    """Bring every pair longer than (1 + max_strain) rest, or shorter than (1 - max_squeeze) rest, to that length
    (silk barely stretches; cloth squeezed more than its mesh can fold buckles instead); returns how many moved."""
    n = 0
    for k in range(pairs.shape[0]):
        a, b = pairs[k, 0], pairs[k, 1]
        dx, dy, dz = p[a, 0] - p[b, 0], p[a, 1] - p[b, 1], p[a, 2] - p[b, 2]
        d2 = dx * dx + dy * dy + dz * dz
        top = (1.0 + max_strain) * rest[k]
        bottom = (1.0 - max_squeeze) * rest[k]
        if d2 < top * top and (d2 > bottom * bottom or d2 < 1e-24):  # most pairs: no square root, no masses
            continue
        w = inv_mass[a] + inv_mass[b]
        if w == 0.0:
            continue
        d = math.sqrt(d2)
        if d <= top and (d >= bottom or d < 1e-12):
            continue
        n += 1
        s = (d - (top if d > top else bottom)) / (d * w)
        p[a, 0] -= inv_mass[a] * s * dx
        p[a, 1] -= inv_mass[a] * s * dy
        p[a, 2] -= inv_mass[a] * s * dz
        p[b, 0] += inv_mass[b] * s * dx
        p[b, 1] += inv_mass[b] * s * dy
        p[b, 2] += inv_mass[b] * s * dz
    return n


@njit(cache=True)
def _capsule_boxes(ends: np.ndarray, radii: np.ndarray, reach: np.ndarray) -> np.ndarray:
    """(n, 6) each tapered capsule's bounding box (min xyz, max xyz) grown by its `reach` (n,) metres."""
    n_caps = ends.shape[0]
    box = np.empty((n_caps, 6))
    for k in range(n_caps):
        r = max(radii[k, 0], radii[k, 1]) + reach[k]
        for c in range(3):
            box[k, c] = min(ends[k, 0, c], ends[k, 1, c]) - r
            box[k, 3 + c] = max(ends[k, 0, c], ends[k, 1, c]) + r
    return box


@njit(cache=True, inline="always")
def _in_box(p: np.ndarray, i: int, box: np.ndarray, k: int, grow: float) -> bool:
    return not (
        p[i, 0] < box[k, 0] - grow or p[i, 0] > box[k, 3] + grow
        or p[i, 1] < box[k, 1] - grow or p[i, 1] > box[k, 4] + grow
        or p[i, 2] < box[k, 2] - grow or p[i, 2] > box[k, 5] + grow
    )  # fmt: skip


@njit(cache=True, inline="always")
def _capsule_point(p: np.ndarray, i: int, ends: np.ndarray, k: int) -> tuple:
    """(t, cx, cy, cz, ux, uy, uz, uu): the parameter along capsule k's axis of the point nearest vertex i, that
    point, and the axis."""
    ax, ay, az = ends[k, 0, 0], ends[k, 0, 1], ends[k, 0, 2]
    ux, uy, uz = ends[k, 1, 0] - ax, ends[k, 1, 1] - ay, ends[k, 1, 2] - az
    uu = ux * ux + uy * uy + uz * uz
    t = 0.0
    if uu > 0.0:
        t = ((p[i, 0] - ax) * ux + (p[i, 1] - ay) * uy + (p[i, 2] - az) * uz) / uu
        t = min(1.0, max(0.0, t))
    return t, ax + t * ux, ay + t * uy, az + t * uz, ux, uy, uz, uu


@njit(cache=True, inline="always")
def _push_out_of_capsule(
    p: np.ndarray,
    x: np.ndarray,
    i: int,
    k: int,
    ends: np.ndarray,
    radii: np.ndarray,
    moved: np.ndarray,
    offset: float,
    friction: float,
) -> bool:
    """Push vertex i out of capsule k plus `offset`, with friction (`collide_capsule_pairs`); whether it was
    inside."""
    t, cx, cy, cz, ux, uy, uz, uu = _capsule_point(p, i, ends, k)
    r = radii[k, 0] + t * (radii[k, 1] - radii[k, 0]) + offset
    nx, ny, nz = p[i, 0] - cx, p[i, 1] - cy, p[i, 2] - cz
    d2 = nx * nx + ny * ny + nz * nz
    if d2 >= r * r:  # most pairs: outside, no square root
        return False
    d = math.sqrt(d2)
    if d < 1e-12:  # on the axis: out along a direction perpendicular to it
        if ux * ux < 0.8 * uu or uu == 0.0:
            nx, ny, nz = 0.0, uz, -uy  # u × x
        else:
            nx, ny, nz = -uz, 0.0, ux  # u × y
        d = max(math.sqrt(nx * nx + ny * ny + nz * nz), 1e-300)
        if uu == 0.0:
            nx, ny, nz, d = 1.0, 0.0, 0.0, 1.0
    nx, ny, nz = nx / d, ny / d, nz / d
    depth = r - d
    p[i, 0] += depth * nx
    p[i, 1] += depth * ny
    p[i, 2] += depth * nz
    # friction: the move relative to the capsule's surface, along the surface
    sx = (1.0 - t) * moved[k, 0, 0] + t * moved[k, 1, 0]
    sy = (1.0 - t) * moved[k, 0, 1] + t * moved[k, 1, 1]
    sz = (1.0 - t) * moved[k, 0, 2] + t * moved[k, 1, 2]
    rx, ry, rz = p[i, 0] - x[i, 0] - sx, p[i, 1] - x[i, 1] - sy, p[i, 2] - x[i, 2] - sz
    rn = rx * nx + ry * ny + rz * nz
    tx, ty, tz = rx - rn * nx, ry - rn * ny, rz - rn * nz
    tl = math.sqrt(tx * tx + ty * ty + tz * tz)
    if tl > 0.0:
        cut = min(1.0, friction * depth / tl)
        p[i, 0] -= cut * tx
        p[i, 1] -= cut * ty
        p[i, 2] -= cut * tz
    return True


@njit(cache=True)
def capsule_candidates(
    p: np.ndarray,
    inv_mass: np.ndarray,
    ends: np.ndarray,
    radii: np.ndarray,
    reach: np.ndarray,
    v: np.ndarray,
    lookahead: float,
    out: np.ndarray,
) -> int:
    """The (vertex, capsule) pairs, vertex by vertex, whose free vertex lies within the capsule's `reach` (n,)
    metres plus
    `lookahead` seconds of its speed (v (V, 3), m/s) of the tapered capsule's surface, into out (V * n, 2) int64;
    returns how many. `collide_capsule_pairs` then tests only these: over the substeps they serve, the collision's
    rounds move the cloth far less than that."""
    box = _capsule_boxes(ends, radii, reach)
    n = 0
    for i in range(p.shape[0]):
        if inv_mass[i] == 0.0:
            continue
        grow = lookahead * math.sqrt(v[i, 0] * v[i, 0] + v[i, 1] * v[i, 1] + v[i, 2] * v[i, 2])
        for k in range(ends.shape[0]):
            if not _in_box(p, i, box, k, grow):
                continue
            t, cx, cy, cz, _, _, _, _ = _capsule_point(p, i, ends, k)
            r = radii[k, 0] + t * (radii[k, 1] - radii[k, 0]) + reach[k] + grow
            if (p[i, 0] - cx) ** 2 + (p[i, 1] - cy) ** 2 + (p[i, 2] - cz) ** 2 < r * r:
                out[n, 0], out[n, 1] = i, k
                n += 1
    return n


@njit(cache=True)
def collide_capsule_pairs(
    p: np.ndarray,
    x: np.ndarray,
    ends: np.ndarray,
    radii: np.ndarray,
    moved: np.ndarray,
    offset: float,
    friction: float,
    pairs: np.ndarray,
    n_pairs: int,
) -> int:
    """Push the vertex of each of the first `n_pairs` (vertex, capsule) pairs (`capsule_candidates`) out of its
    tapered capsule (ends (n, 2, 3), radii (n, 2)) plus `offset` metres, with Coulomb friction: the vertex's move
    this substep relative to the capsule's surface (`moved` (n, 2, 3): how far each capsule end moved this
    substep) loses up to `friction` times the push along the surface. Returns the number of pushes."""
    pushed = 0
    for m in range(n_pairs):
        if _push_out_of_capsule(p, x, pairs[m, 0], pairs[m, 1], ends, radii, moved, offset, friction):
            pushed += 1
    return pushed


@njit(cache=True)
def finish(x: np.ndarray, v: np.ndarray, p: np.ndarray, inv_mass: np.ndarray, h: float, keep: float) -> None:
    """v = (p − x) / h times `keep` (1 − damping over the substep), x = p, for every free vertex."""
    for i in range(x.shape[0]):
        if inv_mass[i] == 0.0:
            for c in range(3):
                v[i, c] = 0.0
            continue
        for c in range(3):
            v[i, c] = keep * (p[i, c] - x[i, c]) / h
            x[i, c] = p[i, c]


@njit(cache=True)
def collide_planes(
    p: np.ndarray,
    x: np.ndarray,
    inv_mass: np.ndarray,
    index: np.ndarray,
    points: np.ndarray,
    normals: np.ndarray,
    moved: np.ndarray,
    offset: float,
    friction: float,
) -> int:
    """Keep the vertices `index` (k,) on the outer side of their skin planes (k, 3) points with unit normals, plus
    `offset` metres, with Coulomb friction against the plane's motion this substep `moved` (k, 3). Returns the
    number pushed."""
    pushed = 0
    for j in range(index.shape[0]):
        i = index[j]
        if inv_mass[i] == 0.0:
            continue
        nx, ny, nz = normals[j, 0], normals[j, 1], normals[j, 2]
        d = (p[i, 0] - points[j, 0]) * nx + (p[i, 1] - points[j, 1]) * ny + (p[i, 2] - points[j, 2]) * nz - offset
        if d >= 0.0:
            continue
        p[i, 0] -= d * nx
        p[i, 1] -= d * ny
        p[i, 2] -= d * nz
        rx = p[i, 0] - x[i, 0] - moved[j, 0]
        ry = p[i, 1] - x[i, 1] - moved[j, 1]
        rz = p[i, 2] - x[i, 2] - moved[j, 2]
        rn = rx * nx + ry * ny + rz * nz
        tx, ty, tz = rx - rn * nx, ry - rn * ny, rz - rn * nz
        tl = math.sqrt(tx * tx + ty * ty + tz * tz)
        if tl > 0.0:
            cut = min(1.0, -friction * d / tl)
            p[i, 0] -= cut * tx
            p[i, 1] -= cut * ty
            p[i, 2] -= cut * tz
        pushed += 1
    return pushed
