"""Plain-numpy references for the cloth kernels: slow, obvious, and computed in a different way where possible
(SVD instead of the closed-form rotation, Rodrigues rotation instead of the flat-target construction)."""

from __future__ import annotations

import numpy as np


def unit(v: np.ndarray) -> np.ndarray:
    n = np.linalg.norm(v, axis=-1, keepdims=True)
    return np.divide(v, n, out=np.zeros_like(v), where=n > 0)


def reference_normals(pos, faces, face_adj, face_adj_sign, active, unflip):
    tri = pos[faces]
    n = unit(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]))
    ok = (face_adj >= 0) & active[np.maximum(face_adj, 0)]
    m = (np.where(ok[..., None], face_adj_sign[..., None] * n[np.maximum(face_adj, 0)], 0.0)).sum(axis=1)
    flipped = active & (np.einsum("ij,ij->i", n, m) < 0) & (np.linalg.norm(m, axis=1) > 1e-6)
    ref = n.copy()
    if unflip:
        ref[flipped] = unit(m[flipped])
    return n, ref, flipped


def shape_match_goals(pos, faces, rest_corners, ref, active):
    """Best rotation of the rest triangle onto the current one projected into the plane with normal `ref`,
    by SVD of the 2D cross-covariance (rotation only: the reflection is removed via the determinant)."""
    goals = pos[faces].copy()
    for t in np.flatnonzero(active):
        x = pos[faces[t]]
        c = x.mean(axis=0)
        n = ref[t]
        e = x[1] - x[0]
        t1 = unit(e - (e @ n) * n)
        t2 = np.cross(n, t1)
        y = np.stack([(x - c) @ t1, (x - c) @ t2], axis=1)
        q = rest_corners[t] - rest_corners[t].mean(axis=0)
        u, _, vt = np.linalg.svd(q.T @ y)  # maximise sum y_i . R q_i
        d = np.sign(np.linalg.det(u @ vt))
        r = (u @ np.diag([1.0, d]) @ vt).T
        rq = q @ r.T
        goals[t] = c + rq[:, :1] * t1 + rq[:, 1:] * t2
    return goals


def rodrigues(v, axis, angle):
    k = axis / np.linalg.norm(axis)
    return v * np.cos(angle) + np.cross(k, v) * np.sin(angle) + k * (k @ v) * (1 - np.cos(angle))


def hinge_deltas(pos, hinges, hinge_faces, active):
    """Turn c and d about the edge by half the missing angle each, in the direction that opens the hinge."""
    out = np.zeros((len(hinges), 4, 3))
    for h, (a, b, c, d) in enumerate(hinges):
        if not (active[hinge_faces[h, 0]] and active[hinge_faces[h, 1]]):
            continue
        e = pos[b] - pos[a]
        cp = pos[c] - pos[a] - ((pos[c] - pos[a]) @ e) / (e @ e) * e
        dp = pos[d] - pos[a] - ((pos[d] - pos[a]) @ e) / (e @ e) * e
        phi = np.arccos(np.clip(unit(cp) @ unit(dp), -1, 1))
        half = 0.5 * (np.pi - phi)
        best = None
        for s in (1.0, -1.0):
            c2, d2 = rodrigues(cp, e, s * half), rodrigues(dp, e, -s * half)
            ang = np.arccos(np.clip(unit(c2) @ unit(d2), -1, 1))
            if best is None or ang > best[0]:
                best = (ang, c2 - cp, d2 - dp)
        _, dc, dd = best
        out[h, 2], out[h, 3] = dc, dd
        out[h, 0] = out[h, 1] = -0.5 * (dc + dd)
    return out


def gather_moves(pos, goals, hinge_d, faces, hinges, hinge_faces, active, pinned, touching, normal, p):
    nv = len(pos)
    s = np.zeros((nv, 3))
    n = np.zeros(nv)
    for t in np.flatnonzero(active):
        for k in range(3):
            s[faces[t, k]] += goals[t, k] - pos[faces[t, k]]
            n[faces[t, k]] += 1
    b = np.zeros((nv, 3))
    m = np.zeros(nv)
    for h in range(len(hinges)):
        if active[hinge_faces[h]].all():
            for k in range(4):
                b[hinges[h, k]] += hinge_d[h, k]
                m[hinges[h, k]] += 1
    move = p.stretch_stiffness * s / np.maximum(n, 1)[:, None] + p.bend_stiffness * b / np.maximum(m, 1)[:, None]
    move[:, 1] -= p.gravity_step_m
    dn = np.einsum("ij,ij->i", move, normal)
    tangent = move - dn[:, None] * normal
    tl = np.linalg.norm(tangent, axis=1)
    keep = np.clip(1 - p.friction * -dn / np.maximum(tl, 1e-300), 0, 1)
    keep = np.where(tl > 0, keep, 0.0)
    rubbed = dn[:, None] * normal + keep[:, None] * tangent
    move = np.where((touching & (dn < 0))[:, None], rubbed, move)
    length = np.linalg.norm(move, axis=1)
    move *= np.minimum(1.0, p.max_step_m / np.maximum(length, 1e-300))[:, None]
    move[(n == 0) | pinned] = 0
    return pos + move


def support_order(pos, roots, active):
    """Supports first, then the other active vertices from the top down (ties by index)."""
    by_height = np.argsort(-pos[:, 1], kind="stable")
    first = [v for v in by_height if roots[v] and active[v]]
    rest = [v for v in by_height if active[v] and not roots[v]]
    return np.array(first + rest, dtype=np.int64)


def limit_strain(pos, order, edges, rest, movable, max_stretch):
    """Gauss-Seidel in `order`: each movable vertex pulled towards its earlier neighbours (by neighbour index)."""
    pos = pos.copy()
    rank = np.full(len(pos), -1)
    rank[order] = np.arange(len(order))
    nbrs = [[] for _ in range(len(pos))]
    for k, (a, b) in enumerate(edges):
        nbrs[a].append((b, k))
        nbrs[b].append((a, k))
    for o, i in enumerate(order):
        if not movable[i]:
            continue
        for j, k in sorted(nbrs[i]):
            if 0 <= rank[j] < o:
                lim = (1 + max_stretch) * rest[k]
                d = pos[i] - pos[j]
                if np.linalg.norm(d) > lim:
                    pos[i] = pos[j] + d * lim / np.linalg.norm(d)
    return pos


def closest_on_triangle(p, a, b, c):
    """Nearest point of triangle abc to p: the plane projection if inside, else the best of the three edges."""
    n = np.cross(b - a, c - a)
    q = p - ((p - a) @ n) / (n @ n) * n
    m = np.array([[*(b - a)], [*(c - a)]]).T
    uv = np.linalg.lstsq(m, q - a, rcond=None)[0]
    if uv.min() >= 0 and uv.sum() <= 1:
        return q
    best = None
    for s0, s1 in ((a, b), (b, c), (c, a)):
        t = np.clip((p - s0) @ (s1 - s0) / ((s1 - s0) @ (s1 - s0)), 0, 1)
        x = s0 + t * (s1 - s0)
        if best is None or np.linalg.norm(p - x) < np.linalg.norm(p - best):
            best = x
    return best


def closest_on_mesh(p, v, f):
    """Brute force over every face (vectorised): project onto each face's plane; where the projection falls
    outside the face, take the nearest of its three edges. Returns (face, point, distance)."""
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    n = np.cross(b - a, c - a)
    q = p - (np.einsum("ij,ij->i", p - a, n) / np.einsum("ij,ij->i", n, n))[:, None] * n
    # Barycentrics of q by areas.
    area = np.einsum("ij,ij->i", n, n)
    u = np.einsum("ij,ij->i", np.cross(c - b, q - b), n) / area
    w = np.einsum("ij,ij->i", np.cross(a - c, q - c), n) / area
    inside = (u >= 0) & (w >= 0) & (1 - u - w >= 0)
    best = np.where(inside[:, None], q, np.inf)
    for s0, s1 in ((a, b), (b, c), (c, a)):
        t = np.clip(np.einsum("ij,ij->i", p - s0, s1 - s0) / np.einsum("ij,ij->i", s1 - s0, s1 - s0), 0, 1)
        x = s0 + t[:, None] * (s1 - s0)
        closer = np.linalg.norm(p - x, axis=1) < np.linalg.norm(p - best, axis=1)
        best = np.where((closer & ~inside)[:, None], x, best)
    d = np.linalg.norm(best - p, axis=1)
    k = int(np.argmin(d))
    return k, best[k], d[k]


def segment_segment_distance(p1, q1, p2, q2, samples: int = 20001):
    """Distance between two segments by dense sampling of the first, exact clamped projection on the second."""
    s = np.linspace(0, 1, samples)[:, None]
    x = p1 + s * (q1 - p1)
    u = q2 - p2
    t = np.clip((x - p2) @ u / (u @ u), 0, 1)[:, None]
    return np.linalg.norm(x - (p2 + t * u), axis=1).min()


def project_lengths(pos, edges, rest, movable, order, omega=1.0, band=0.0):
    """One Gauss-Seidel sweep in `order`: each edge's movable ends moved along it, equally, to its rest length
    (omega times the way there); with band > 0, only an edge longer than (1 + band) rest or shorter than
    (1 - band) rest, and only to that length."""
    pos = pos.copy()
    worst = 0.0
    for e in order:
        a, b = edges[e]
        w = np.array([movable[a], movable[b]], dtype=float)
        if w.sum() == 0:
            continue
        d = pos[b] - pos[a]
        length = np.linalg.norm(d)
        target = np.clip(length, (1 - band) * rest[e], (1 + band) * rest[e])
        if target == length:
            continue
        worst = max(worst, abs(length - target))
        corr = omega * (length - target) / w.sum() * d / length
        pos[a] += w[0] * corr
        pos[b] -= w[1] * corr
    return pos, worst


def project_tethers(pos, tri, bary, movable, lines, line_of, reach):
    """One sweep of tethers: each cloth point (barycentric in its triangle) farther than `reach` from its polyline
    (lines[line_of[i]], (k, 3); one point: that point) is moved towards the polyline's nearest point until it is
    `reach` away, its vertices sharing the move in proportion to their barycentric weight; a point with a fixed
    vertex stays."""
    pos = pos.copy()
    worst = 0.0
    for i in range(len(tri)):
        if not movable[tri[i]].all():
            continue
        p = bary[i] @ pos[tri[i]]
        line = lines[line_of[i]]
        best, q = np.inf, None
        for a, b in zip(line[:-1], line[1:], strict=True) if len(line) > 1 else [(line[0], line[0])]:
            e = b - a
            t = 0.0 if e @ e <= 1e-24 else float(np.clip((p - a) @ e / (e @ e), 0.0, 1.0))
            c = a + t * e
            if np.linalg.norm(p - c) < best:
                best, q = np.linalg.norm(p - c), c
        over = best - reach
        if over <= 0:
            continue
        worst = max(worst, over)
        for k in range(3):
            pos[tri[i, k]] += bary[i, k] / (bary[i] @ bary[i]) * over / best * (q - p)
    return pos, worst


def layer_moves(pos, faces, face_layer, vertex_layer, movable, reach, gap, max_step, outward=None, near=None):
    """`keep_layers`' moves (V, 3) by brute force: every vertex with a layer against every face of another layer
    that does not hold it (`closest_on_mesh`), then the side rules of `_collide_kernels.layer_moves`. outward
    (V, 3), near (V,) bool: the body's outward normal at each vertex and whether it lies within reach of the
    body; a face normal more than 120 degrees from it is turned round."""
    out = np.zeros_like(pos)
    for v in np.flatnonzero((vertex_layer > 0) & movable):
        mine = vertex_layer[v]
        cand = np.flatnonzero((face_layer > 0) & (face_layer != mine) & ~(faces == v).any(axis=1))
        if not len(cand):
            continue
        k, q, d = closest_on_mesh(pos[v], pos, faces[cand])
        if d >= reach:
            continue
        a, b, c = pos[faces[cand[k]]]
        n = unit(np.cross(b - a, c - a))
        if outward is not None and near[v] and n @ outward[v] < -0.5:
            n = -n
        h = (pos[v] - q) @ n
        if d * d - h * h > (0.5 * abs(h) + 1e-3) ** 2:  # beside the other layer's border
            continue
        s = 1.0 if mine > face_layer[cand[k]] else -1.0
        short = gap - s * h
        if short > 0:
            out[v] = s * min(0.5 * short, max_step) * n
    return out
