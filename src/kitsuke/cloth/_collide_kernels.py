"""numba kernels of the body collision (private: call them through `kitsuke.cloth.collide` / `track`).

Nearest-surface tracking after Skin (Markosian et al. 1999) as the paper uses it: every cloth vertex keeps the body
face of its nearest point and walks from it to neighbouring faces while the nearest point gets closer. Region
codes of a point on a triangle: 0 inside, 1..3 at corner 0..2, 4..6 on edge 01, 12, 20.
"""

from __future__ import annotations

import math
import os

import numpy as np
from numba import njit, prange

PARALLEL = os.environ.get("KITSUKE_NUMBA_PARALLEL", "1") != "0"

#: Relative decrease of the squared distance a walk step must achieve; equal distances (a point on a shared edge
#: or corner) stop the walk instead of cycling.
WALK_IMPROVEMENT = 1e-10


@njit(cache=True)
def closest_on_triangle(px, py, pz, bv, i0, i1, i2):
    """Nearest point of triangle (bv[i0], bv[i1], bv[i2]) to p: (cx, cy, cz, b0, b1, b2, region)."""
    ax, ay, az = bv[i0, 0], bv[i0, 1], bv[i0, 2]
    abx, aby, abz = bv[i1, 0] - ax, bv[i1, 1] - ay, bv[i1, 2] - az
    acx, acy, acz = bv[i2, 0] - ax, bv[i2, 1] - ay, bv[i2, 2] - az
    apx, apy, apz = px - ax, py - ay, pz - az
    d1 = abx * apx + aby * apy + abz * apz
    d2 = acx * apx + acy * apy + acz * apz
    if d1 <= 0.0 and d2 <= 0.0:
        return ax, ay, az, 1.0, 0.0, 0.0, 1
    bpx, bpy, bpz = px - bv[i1, 0], py - bv[i1, 1], pz - bv[i1, 2]
    d3 = abx * bpx + aby * bpy + abz * bpz
    d4 = acx * bpx + acy * bpy + acz * bpz
    if d3 >= 0.0 and d4 <= d3:
        return bv[i1, 0], bv[i1, 1], bv[i1, 2], 0.0, 1.0, 0.0, 2
    vc = d1 * d4 - d3 * d2
    if vc <= 0.0 and d1 >= 0.0 and d3 <= 0.0:
        v = d1 / (d1 - d3)
        return ax + v * abx, ay + v * aby, az + v * abz, 1.0 - v, v, 0.0, 4
    cpx, cpy, cpz = px - bv[i2, 0], py - bv[i2, 1], pz - bv[i2, 2]
    d5 = abx * cpx + aby * cpy + abz * cpz
    d6 = acx * cpx + acy * cpy + acz * cpz
    if d6 >= 0.0 and d5 <= d6:
        return bv[i2, 0], bv[i2, 1], bv[i2, 2], 0.0, 0.0, 1.0, 3
    vb = d5 * d2 - d1 * d6
    if vb <= 0.0 and d2 >= 0.0 and d6 <= 0.0:
        w = d2 / (d2 - d6)
        return ax + w * acx, ay + w * acy, az + w * acz, 1.0 - w, 0.0, w, 6
    va = d3 * d6 - d5 * d4
    if va <= 0.0 and d4 - d3 >= 0.0 and d5 - d6 >= 0.0:
        w = (d4 - d3) / ((d4 - d3) + (d5 - d6))
        bx, by, bz = bv[i1, 0], bv[i1, 1], bv[i1, 2]
        return bx + w * (bv[i2, 0] - bx), by + w * (bv[i2, 1] - by), bz + w * (bv[i2, 2] - bz), 0.0, 1.0 - w, w, 5
    s = va + vb + vc
    if s <= 0.0:  # degenerate triangle: its first corner
        return ax, ay, az, 1.0, 0.0, 0.0, 1
    v, w = vb / s, vc / s
    return ax + v * abx + w * acx, ay + v * aby + w * acy, az + v * abz + w * acz, 1.0 - v - w, v, w, 0


@njit(cache=True)
def _pseudo_normal(f, region, bf, face_n, edge_n, vert_n):
    """Angle-weighted pseudo-normal of the feature `region` of face f: its sign test is exact for the true
    nearest point of a closed mesh (Baerentzen & Aanaes 2005)."""
    if region == 0:
        return face_n[f, 0], face_n[f, 1], face_n[f, 2]
    if region <= 3:
        v = bf[f, region - 1]
        return vert_n[v, 0], vert_n[v, 1], vert_n[v, 2]
    k = region - 4
    return edge_n[f, k, 0], edge_n[f, k, 1], edge_n[f, k, 2]


@njit(cache=True)
def _store(
    i,
    px,
    py,
    pz,
    f,
    cx,
    cy,
    cz,
    b0,
    b1,
    b2,
    region,
    bf,
    face_n,
    edge_n,
    vert_n,
    smooth_n,
    c_face,
    c_bary,
    c_point,
    c_normal,
    c_dist,
):
    """Write one vertex's contact: face, barycentrics, point, interpolated normal and signed distance."""
    dx, dy, dz = px - cx, py - cy, pz - cz
    d = math.sqrt(dx * dx + dy * dy + dz * dz)
    sx, sy, sz = _pseudo_normal(f, region, bf, face_n, edge_n, vert_n)
    if dx * sx + dy * sy + dz * sz < 0.0:
        d = -d
    j0, j1, j2 = bf[f, 0], bf[f, 1], bf[f, 2]
    nx = b0 * smooth_n[j0, 0] + b1 * smooth_n[j1, 0] + b2 * smooth_n[j2, 0]
    ny = b0 * smooth_n[j0, 1] + b1 * smooth_n[j1, 1] + b2 * smooth_n[j2, 1]
    nz = b0 * smooth_n[j0, 2] + b1 * smooth_n[j1, 2] + b2 * smooth_n[j2, 2]
    n = math.sqrt(nx * nx + ny * ny + nz * nz)
    if n > 0.0:
        nx, ny, nz = nx / n, ny / n, nz / n
    else:
        nx, ny, nz = face_n[f, 0], face_n[f, 1], face_n[f, 2]
    c_face[i] = f
    c_bary[i, 0], c_bary[i, 1], c_bary[i, 2] = b0, b1, b2
    c_point[i, 0], c_point[i, 1], c_point[i, 2] = cx, cy, cz
    c_normal[i, 0], c_normal[i, 1], c_normal[i, 2] = nx, ny, nz
    c_dist[i] = d
    return d


@njit(cache=True, parallel=PARALLEL)
def walk_track(
    pos,
    active,
    bv,
    bf,
    face_adj,
    vf_ptr,
    vf,
    face_n,
    edge_n,
    vert_n,
    smooth_n,
    max_steps,
    track_m,
    contact_m,
    c_face,
    c_bary,
    c_point,
    c_normal,
    c_dist,
    c_anchor,
    c_anchor_d,
    out_search,
):
    """Update each active vertex's nearest body point by walking from its tracked face (in place on the c_*
    contact arrays). out_search (V,) uint8 is set to 1 where a global search is needed: the vertex is untracked,
    the walk ran out of steps, or it lies farther than `track_m` and may have come within `contact_m` of the body
    since its last trusted result (anchor). Vertices closer than `track_m` renew their anchor.
    """
    nv = pos.shape[0]
    for i in prange(nv):
        out_search[i] = 0
        if not active[i]:
            continue
        f = c_face[i]
        if f < 0:
            out_search[i] = 1
            continue
        px, py, pz = pos[i, 0], pos[i, 1], pos[i, 2]
        cx, cy, cz, b0, b1, b2, region = closest_on_triangle(px, py, pz, bv, bf[f, 0], bf[f, 1], bf[f, 2])
        d2 = (px - cx) ** 2 + (py - cy) ** 2 + (pz - cz) ** 2
        ok = False
        for _ in range(max_steps):
            if region == 0:
                ok = True
                break
            best, bd2 = -1, d2 * (1.0 - WALK_IMPROVEMENT)
            bcx, bcy, bcz, bb0, bb1, bb2, breg = cx, cy, cz, b0, b1, b2, region
            if region >= 4:
                g = face_adj[f, region - 4]
                if g >= 0:
                    qx, qy, qz, q0, q1, q2, qr = closest_on_triangle(px, py, pz, bv, bf[g, 0], bf[g, 1], bf[g, 2])
                    e2 = (px - qx) ** 2 + (py - qy) ** 2 + (pz - qz) ** 2
                    if e2 < bd2:
                        best, bd2 = g, e2
                        bcx, bcy, bcz, bb0, bb1, bb2, breg = qx, qy, qz, q0, q1, q2, qr
            else:
                v = bf[f, region - 1]
                for j in range(vf_ptr[v], vf_ptr[v + 1]):
                    g = vf[j]
                    if g == f:
                        continue
                    qx, qy, qz, q0, q1, q2, qr = closest_on_triangle(px, py, pz, bv, bf[g, 0], bf[g, 1], bf[g, 2])
                    e2 = (px - qx) ** 2 + (py - qy) ** 2 + (pz - qz) ** 2
                    if e2 < bd2:
                        best, bd2 = g, e2
                        bcx, bcy, bcz, bb0, bb1, bb2, breg = qx, qy, qz, q0, q1, q2, qr
            if best < 0:
                ok = True
                break
            f, d2 = best, bd2
            cx, cy, cz, b0, b1, b2, region = bcx, bcy, bcz, bb0, bb1, bb2, breg
        if not ok:
            out_search[i] = 1
            continue
        d = math.sqrt(d2)
        if d > track_m:
            ax, ay, az = px - c_anchor[i, 0], py - c_anchor[i, 1], pz - c_anchor[i, 2]
            moved = math.sqrt(ax * ax + ay * ay + az * az)
            if moved >= c_anchor_d[i] - contact_m:
                out_search[i] = 1
                continue
        sd = _store(
            i,
            px,
            py,
            pz,
            f,
            cx,
            cy,
            cz,
            b0,
            b1,
            b2,
            region,
            bf,
            face_n,
            edge_n,
            vert_n,
            smooth_n,
            c_face,
            c_bary,
            c_point,
            c_normal,
            c_dist,
        )
        if d <= track_m:
            c_anchor[i, 0], c_anchor[i, 1], c_anchor[i, 2] = px, py, pz
            c_anchor_d[i] = sd


@njit(cache=True)
def store_found(
    pos,
    idx,
    found_face,
    bv,
    bf,
    face_n,
    edge_n,
    vert_n,
    smooth_n,
    c_face,
    c_bary,
    c_point,
    c_normal,
    c_dist,
    c_anchor,
    c_anchor_d,
):
    """Write the contacts of vertices idx (n,) whose nearest body face a global search found (found_face (n,)),
    and make their positions the new anchors."""
    for j in range(idx.shape[0]):
        i, f = idx[j], found_face[j]
        px, py, pz = pos[i, 0], pos[i, 1], pos[i, 2]
        cx, cy, cz, b0, b1, b2, region = closest_on_triangle(px, py, pz, bv, bf[f, 0], bf[f, 1], bf[f, 2])
        sd = _store(
            i,
            px,
            py,
            pz,
            f,
            cx,
            cy,
            cz,
            b0,
            b1,
            b2,
            region,
            bf,
            face_n,
            edge_n,
            vert_n,
            smooth_n,
            c_face,
            c_bary,
            c_point,
            c_normal,
            c_dist,
        )
        c_anchor[i, 0], c_anchor[i, 1], c_anchor[i, 2] = px, py, pz
        c_anchor_d[i] = sd


@njit(cache=True)
def vertex_grid(bv, cell):
    """Bin the points bv (n, 3) into cubes of side `cell` metres (a counting sort): origin (3,), dims (3,) int64,
    start (cells + 1,) int64, items (n,) int64; the points of cell (i, j, k) are items[start[c]:start[c + 1]] with
    c = (i * dims[1] + j) * dims[2] + k."""
    n = bv.shape[0]
    origin = np.empty(3)
    dims = np.empty(3, dtype=np.int64)
    for a in range(3):
        lo, hi = np.inf, -np.inf
        for v in range(n):
            lo = min(lo, bv[v, a])
            hi = max(hi, bv[v, a])
        origin[a] = lo
        dims[a] = max(1, int((hi - lo) / cell) + 1)
    n_cells = dims[0] * dims[1] * dims[2]
    of = np.empty(n, dtype=np.int64)
    start = np.zeros(n_cells + 1, dtype=np.int64)
    for v in range(n):
        c = 0
        for a in range(3):
            c = c * dims[a] + min(dims[a] - 1, int((bv[v, a] - origin[a]) / cell))
        of[v] = c
        start[c + 1] += 1
    for c in range(n_cells):
        start[c + 1] += start[c]
    fill = start[:-1].copy()
    items = np.empty(n, dtype=np.int64)
    for v in range(n):
        items[fill[of[v]]] = v
        fill[of[v]] += 1
    return origin, dims, start, items


@njit(cache=True)
def _grid_nearest(px, py, pz, bv, origin, dims, cell, start, items):
    """The point of the grid (`vertex_grid`) nearest (px, py, pz): rings of cells outwards from the point's cell
    (clamped into the grid) until no farther ring can hold a nearer point. Exact, as a pass over all points."""
    q = (px, py, pz)
    home = np.empty(3, dtype=np.int64)
    for a in range(3):
        home[a] = min(dims[a] - 1, max(0, int(math.floor((q[a] - origin[a]) / cell))))
    best, bd2 = -1, np.inf
    reach = max(dims[0], max(dims[1], dims[2]))
    for r in range(reach + 1):
        for i in range(max(0, home[0] - r), min(dims[0] - 1, home[0] + r) + 1):
            for j in range(max(0, home[1] - r), min(dims[1] - 1, home[1] + r) + 1):
                shell = abs(i - home[0]) == r or abs(j - home[1]) == r
                for k in range(max(0, home[2] - r), min(dims[2] - 1, home[2] + r) + 1):
                    if not shell and abs(k - home[2]) != r:
                        continue  # inside the ring: seen in an earlier one
                    c = (i * dims[1] + j) * dims[2] + k
                    for m in range(start[c], start[c + 1]):
                        v = items[m]
                        d2 = (bv[v, 0] - px) ** 2 + (bv[v, 1] - py) ** 2 + (bv[v, 2] - pz) ** 2
                        if d2 < bd2:
                            best, bd2 = v, d2
        # a point in ring r + 1 or beyond is at least r cells away from any point of the home cell
        if best >= 0 and bd2 <= (r * cell) ** 2:
            break
    return best


@njit(cache=True, parallel=PARALLEL)
def seed_faces(pos, idx, bv, bf, vf_ptr, vf, origin, dims, cell, start, items, out_face):
    """For the vertices idx (n,): of the body faces around the body vertex nearest each (found in the body's
    vertex grid, `vertex_grid`), the one with the nearest point, in out_face (n,). A start for `walk_track`, which
    descends from it to the nearest point."""
    for j in prange(idx.shape[0]):
        i = idx[j]
        px, py, pz = pos[i, 0], pos[i, 1], pos[i, 2]
        best = _grid_nearest(px, py, pz, bv, origin, dims, cell, start, items)
        face, fd2 = 0, np.inf
        for k in range(vf_ptr[best], vf_ptr[best + 1]):
            g = vf[k]
            qx, qy, qz, _, _, _, _ = closest_on_triangle(px, py, pz, bv, bf[g, 0], bf[g, 1], bf[g, 2])
            e2 = (px - qx) ** 2 + (py - qy) ** 2 + (pz - qz) ** 2
            if e2 < fd2:
                face, fd2 = g, e2
        out_face[j] = face


@njit(cache=True, parallel=PARALLEL)
def push_out(pos, movable, offset, c_face, c_normal, c_dist):
    """Move each movable tracked vertex closer to the body than `offset` (or inside) along the interpolated body
    normal until it is `offset` outside (in place; updates c_dist). Returns (vertices moved, deepest depth inside
    before the move, metres)."""
    nv = pos.shape[0]
    pushed = 0
    deepest = 0.0
    for i in prange(nv):
        if movable[i] and c_face[i] >= 0 and c_dist[i] < offset:
            d = c_dist[i]
            deepest = max(deepest, -d)
            pushed += 1
            s = offset - d
            pos[i, 0] += s * c_normal[i, 0]
            pos[i, 1] += s * c_normal[i, 1]
            pos[i, 2] += s * c_normal[i, 2]
            c_dist[i] = offset
    return pushed, deepest


@njit(cache=True)
def _segment_point(px, py, pz, ax, ay, az, bx, by, bz):
    """Parameter t in [0, 1] of the point of segment a-b nearest p."""
    ux, uy, uz = bx - ax, by - ay, bz - az
    uu = ux * ux + uy * uy + uz * uz
    if uu <= 0.0:
        return 0.0
    t = ((px - ax) * ux + (py - ay) * uy + (pz - az) * uz) / uu
    return min(1.0, max(0.0, t))


@njit(cache=True, parallel=PARALLEL)
def capsule_vertices(pos, movable, ends, radii, lo, hi, margin, out_near):
    """Push movable vertices out of tapered capsules (in place): a vertex nearer a capsule's axis than the radius
    there (linear between the end radii, at the axis point nearest the vertex) moves radially to that radius.

    lo, hi (C, 3): each capsule's bounding box. out_near (V,) int64: bit c set where the vertex is within
    `margin` metres of capsule c's box (so edges need only test the capsules near their ends; C <= 63).
    """
    nv, nc = pos.shape[0], ends.shape[0]
    for i in prange(nv):
        bits = 0
        for c in range(nc):
            px, py, pz = pos[i, 0], pos[i, 1], pos[i, 2]
            if (
                px < lo[c, 0] - margin
                or px > hi[c, 0] + margin
                or py < lo[c, 1] - margin
                or py > hi[c, 1] + margin
                or pz < lo[c, 2] - margin
                or pz > hi[c, 2] + margin
            ):
                continue
            bits |= 1 << c
            if not movable[i]:
                continue
            ax, ay, az = ends[c, 0, 0], ends[c, 0, 1], ends[c, 0, 2]
            bx, by, bz = ends[c, 1, 0], ends[c, 1, 1], ends[c, 1, 2]
            t = _segment_point(px, py, pz, ax, ay, az, bx, by, bz)
            r = radii[c, 0] + t * (radii[c, 1] - radii[c, 0])
            qx, qy, qz = ax + t * (bx - ax), ay + t * (by - ay), az + t * (bz - az)
            dx, dy, dz = px - qx, py - qy, pz - qz
            d = math.sqrt(dx * dx + dy * dy + dz * dz)
            if d >= r:
                continue
            if d <= 1e-12:  # on the axis: out along any perpendicular
                ux, uy, uz = bx - ax, by - ay, bz - az
                dx, dy, dz = (
                    (uy, -ux, 0.0) if abs(uz) < 0.9 * math.sqrt(ux * ux + uy * uy + uz * uz) else (0.0, uz, -uy)
                )
                d = math.sqrt(dx * dx + dy * dy + dz * dz)
                if d == 0.0:
                    dx, dy, dz, d = 1.0, 0.0, 0.0, 1.0
            f = r / d
            pos[i, 0], pos[i, 1], pos[i, 2] = qx + dx * f, qy + dy * f, qz + dz * f
        out_near[i] = bits


@njit(cache=True)
def segment_segment(p1x, p1y, p1z, q1x, q1y, q1z, p2x, p2y, p2z, q2x, q2y, q2z):
    """Parameters (s, t) in [0, 1] of the nearest points of segments p1-q1 and p2-q2 (clamped closest points)."""
    d1x, d1y, d1z = q1x - p1x, q1y - p1y, q1z - p1z
    d2x, d2y, d2z = q2x - p2x, q2y - p2y, q2z - p2z
    rx, ry, rz = p1x - p2x, p1y - p2y, p1z - p2z
    a = d1x * d1x + d1y * d1y + d1z * d1z
    e = d2x * d2x + d2y * d2y + d2z * d2z
    f = d2x * rx + d2y * ry + d2z * rz
    if a <= 1e-300 and e <= 1e-300:
        return 0.0, 0.0
    if a <= 1e-300:
        return 0.0, min(1.0, max(0.0, f / e))
    c = d1x * rx + d1y * ry + d1z * rz
    if e <= 1e-300:
        return min(1.0, max(0.0, -c / a)), 0.0
    b = d1x * d2x + d1y * d2y + d1z * d2z
    den = a * e - b * b
    s = min(1.0, max(0.0, (b * f - c * e) / den)) if den > 1e-300 else 0.0
    t = (b * s + f) / e
    if t < 0.0:
        t = 0.0
        s = min(1.0, max(0.0, -c / a))
    elif t > 1.0:
        t = 1.0
        s = min(1.0, max(0.0, (b - c) / a))
    return s, t


@njit(cache=True)
def capsule_edges(pos, edges, movable, ends, radii, near):
    """Push cloth edges out of tapered capsules (in place, Gauss-Seidel over edges): where an edge's nearest point
    to a capsule axis lies inside the capsule, its two vertices move along the separating direction so that this
    point reaches the capsule surface (weighted by where along the edge it lies; a held vertex takes no share).
    near (V,) int64: the capsule bits of `capsule_vertices`; an edge tests the capsules near either end.
    """
    for e in range(edges.shape[0]):
        i, j = edges[e, 0], edges[e, 1]
        bits = near[i] | near[j]
        if bits == 0 or not (movable[i] or movable[j]):
            continue
        c = 0
        while bits != 0:
            if bits & 1:
                ax, ay, az = ends[c, 0, 0], ends[c, 0, 1], ends[c, 0, 2]
                bx, by, bz = ends[c, 1, 0], ends[c, 1, 1], ends[c, 1, 2]
                s, t = segment_segment(
                    pos[i, 0], pos[i, 1], pos[i, 2], pos[j, 0], pos[j, 1], pos[j, 2], ax, ay, az, bx, by, bz
                )
                r = radii[c, 0] + t * (radii[c, 1] - radii[c, 0])
                ex = pos[i, 0] + s * (pos[j, 0] - pos[i, 0]) - (ax + t * (bx - ax))
                ey = pos[i, 1] + s * (pos[j, 1] - pos[i, 1]) - (ay + t * (by - ay))
                ez = pos[i, 2] + s * (pos[j, 2] - pos[i, 2]) - (az + t * (bz - az))
                d = math.sqrt(ex * ex + ey * ey + ez * ez)
                # Outside, or exactly on the axis (no direction; the vertex pass handles ends).
                if r > d > 1e-12:
                    wi = (1.0 - s) if movable[i] else 0.0
                    wj = s if movable[j] else 0.0
                    ww = wi * wi + wj * wj
                    # Skip when only a held vertex's near end is inside: moving the other end would fling it.
                    if ww > 1e-2:
                        k = (r - d) / (d * ww)  # moves the edge point by (r - d) along e / d
                        pos[i, 0] += wi * k * ex
                        pos[i, 1] += wi * k * ey
                        pos[i, 2] += wi * k * ez
                        pos[j, 0] += wj * k * ex
                        pos[j, 1] += wj * k * ey
                        pos[j, 2] += wj * k * ez
            bits >>= 1
            c += 1


@njit(cache=True)
def point_grid(pos, ids, cell, max_cells):
    """A uniform grid of the points `ids` (G,): (origin (3,), cell size, dims (3,) int64, ptr (C + 1,), items (G,)
    int64 point ids by cell). The cell size doubles from `cell` until the grid has at most `max_cells` cells."""
    lo = np.full(3, np.inf)
    hi = np.full(3, -np.inf)
    for i in range(ids.shape[0]):
        for a in range(3):
            lo[a] = min(lo[a], pos[ids[i], a])
            hi[a] = max(hi[a], pos[ids[i], a])
    dims = np.ones(3, dtype=np.int64)
    if ids.shape[0] == 0:
        return lo, cell, dims, np.zeros(2, dtype=np.int64), np.zeros(0, dtype=np.int64)
    while True:
        for a in range(3):
            dims[a] = int((hi[a] - lo[a]) / cell) + 1
        if dims[0] * dims[1] * dims[2] <= max_cells:
            break
        cell *= 2.0
    n_cells = dims[0] * dims[1] * dims[2]
    key = np.empty(ids.shape[0], dtype=np.int64)
    ptr = np.zeros(n_cells + 1, dtype=np.int64)
    for i in range(ids.shape[0]):
        x = min(int((pos[ids[i], 0] - lo[0]) / cell), dims[0] - 1)
        y = min(int((pos[ids[i], 1] - lo[1]) / cell), dims[1] - 1)
        z = min(int((pos[ids[i], 2] - lo[2]) / cell), dims[2] - 1)
        key[i] = (x * dims[1] + y) * dims[2] + z
        ptr[key[i] + 1] += 1
    for c in range(n_cells):
        ptr[c + 1] += ptr[c]
    fill = ptr[:-1].copy()
    items = np.empty(ids.shape[0], dtype=np.int64)
    for i in range(ids.shape[0]):
        items[fill[key[i]]] = ids[i]
        fill[key[i]] += 1
    return lo, cell, dims, ptr, items


@njit(cache=True, parallel=PARALLEL)
def layer_moves(
    pos,
    faces,
    face_layer,
    face_active,
    vertex_layer,
    layers_at,
    corners_ptr,
    corners,
    c_face,
    c_normal,
    c_dist,
    query,
    origin,
    cell,
    dims,
    ptr,
    items,
    grid_pos,
    reach,
    gap,
    max_step,
    out,
    out_face,
    out_bary,
    out_normal,
):
    """Moves (Q, 3) into `out` that restore the order of cloth layers at the vertices `query` (Q,): a vertex of
    layer a nearest (within `reach`) to a face of another layer b must lie at least `gap` outside that face
    (along its normal, the winding's outer side) where a > b, and `gap` inside it where a < b. A vertex that
    violates this takes half the shortfall (the other layer's vertices take the other half in their own query),
    at most `max_step`. Points beside the other layer's border (nearest point on its boundary, off to the side
    by more than half their height over it plus 1 mm) are not between the layers and are left alone. "Outside"
    is away from the body: where the vertex is tracked (c_face >= 0) the face normal is turned to agree with the
    body's outward normal there (c_normal), so cloth lying inside out (a collar twisted over) still keeps the
    order. Only where the vertex lies within `reach` of the body (c_dist) and the face clearly faces it (normals
    more than 120 degrees apart): farther out, the nearest body point (a thigh beside a hanging hem) says little
    about which way is out. Elsewhere the winding alone decides.

    The nearest face is searched among the faces around the nearest vertex that lies on a face of another layer
    (and the next two nearest where the nearest point found lies on the rim of that fan). Grid (`items`, cells of
    at least `reach` plus most of an edge; grid_pos: their positions in grid order); `layers_at`: bit l set where
    a vertex has a face of layer l; inactive faces are skipped; corners_ptr, corners: CSR of the corners
    (face * 3 + k) at each vertex.
    Each vertex's constraint goes to out_face (Q,) (the other layer's face, -1 where none applies), out_bary
    (Q, 3) (the nearest point's barycentric coordinates in it) and out_normal (Q, 3) (the unit direction the
    vertex must lie along from that point: (x_v - point) . out_normal >= gap), violated or not: the polish keeps
    them as planes (`layer_planes`).
    Returns the number of vertices moved."""
    moved = 0
    for qi in prange(query.shape[0]):
        out[qi, 0] = out[qi, 1] = out[qi, 2] = 0.0
        out_face[qi] = -1
        v = query[qi]
        lv = vertex_layer[v]
        px, py, pz = pos[v, 0], pos[v, 1], pos[v, 2]
        cx = int(math.floor((px - origin[0]) / cell))
        cy = int(math.floor((py - origin[1]) / cell))
        cz = int(math.floor((pz - origin[2]) / cell))
        # The three nearest candidates, nearest first (scalars: an array per vertex costs an allocation).
        c0 = c1 = c2 = -1
        d0 = d1 = d2 = cell * cell
        bit = np.int64(1) << lv
        for x in range(max(cx - 1, 0), min(cx + 2, dims[0])):
            for y in range(max(cy - 1, 0), min(cy + 2, dims[1])):
                # The z cells of one (x, y) are consecutive: one run of items.
                c = (x * dims[1] + y) * dims[2]
                for j in range(ptr[c + max(cz - 1, 0)], ptr[c + min(cz + 2, dims[2])]):
                    u = items[j]
                    if layers_at[u] & ~bit == 0:
                        continue
                    d = (px - grid_pos[j, 0]) ** 2 + (py - grid_pos[j, 1]) ** 2 + (pz - grid_pos[j, 2]) ** 2
                    if d >= d2:
                        continue
                    if d < d0:
                        c2, d2, c1, d1, c0, d0 = c1, d1, c0, d0, u, d
                    elif d < d1:
                        c2, d2, c1, d1 = c1, d1, u, d
                    else:
                        c2, d2 = u, d
        best = reach * reach
        bf = -1
        bqx = bqy = bqz = 0.0
        bb0 = bb1 = bb2 = 0.0
        for k in range(3):
            u = c0 if k == 0 else (c1 if k == 1 else c2)
            if u < 0:
                break
            fan_edge = False  # the best point so far lies on the far rim of u's fan: the next candidate may beat it
            for j in range(corners_ptr[u], corners_ptr[u + 1]):
                f = corners[j] // 3
                i0, i1, i2 = faces[f, 0], faces[f, 1], faces[f, 2]
                if face_layer[f] == 0 or face_layer[f] == lv or not face_active[f] or i0 == v or i1 == v or i2 == v:
                    continue
                qx, qy, qz, b0, b1, b2, region = closest_on_triangle(px, py, pz, pos, i0, i1, i2)
                dq = (px - qx) ** 2 + (py - qy) ** 2 + (pz - qz) ** 2
                if dq < best:
                    best, bf, bqx, bqy, bqz = dq, f, qx, qy, qz
                    bb0, bb1, bb2 = b0, b1, b2
                    # Corner u is corners[j] % 3; the rim is the edge opposite it and its two far corners.
                    ku = corners[j] % 3
                    rim_edge = 4 + (ku + 1) % 3  # edge codes 4, 5, 6: edges 01, 12, 20
                    fan_edge = region == rim_edge or (1 <= region <= 3 and region - 1 != ku)
            if bf >= 0 and not fan_edge:
                break
        if bf < 0:
            continue
        i0, i1, i2 = faces[bf, 0], faces[bf, 1], faces[bf, 2]
        ax, ay, az = pos[i1, 0] - pos[i0, 0], pos[i1, 1] - pos[i0, 1], pos[i1, 2] - pos[i0, 2]
        bx, by, bz = pos[i2, 0] - pos[i0, 0], pos[i2, 1] - pos[i0, 1], pos[i2, 2] - pos[i0, 2]
        nx, ny, nz = ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx
        nn = math.sqrt(nx * nx + ny * ny + nz * nz)
        if nn <= 1e-20:
            continue
        nx, ny, nz = nx / nn, ny / nn, nz / nn
        if (
            c_face[v] >= 0
            and c_dist[v] < reach
            and nx * c_normal[v, 0] + ny * c_normal[v, 1] + nz * c_normal[v, 2] < -0.5
        ):
            nx, ny, nz = -nx, -ny, -nz
        h = (px - bqx) * nx + (py - bqy) * ny + (pz - bqz) * nz
        side = max(best - h * h, 0.0)
        if side > (0.5 * abs(h) + 1e-3) ** 2:
            continue
        s = 1.0 if lv > face_layer[bf] else -1.0
        out_face[qi] = bf
        out_bary[qi, 0], out_bary[qi, 1], out_bary[qi, 2] = bb0, bb1, bb2
        out_normal[qi, 0], out_normal[qi, 1], out_normal[qi, 2] = s * nx, s * ny, s * nz
        short = gap - s * h
        if short <= 0.0:
            continue
        m = s * min(0.5 * short, max_step)
        out[qi, 0], out[qi, 1], out[qi, 2] = m * nx, m * ny, m * nz
        moved += 1
    return moved


def set_parallel(parallel: bool) -> None:
    """Recompile the per-vertex kernels with or without threads (for benchmarks; not cached)."""
    g = globals()
    for name in ("walk_track", "push_out", "capsule_vertices", "layer_moves"):
        g[name] = njit(parallel=parallel)(g[name].py_func)


@njit(cache=True)
def surface_normals(v, f, adj, angles, face_n, edge_n, vert_n):
    """A closed surface's normals, into face_n (F, 3), edge_n (F, 3, 3) and vert_n (V, 3) (`BodyCollider`'s: unit
    face normals, each edge's mean of its two faces' normals, vertex normals weighted by the corner `angles`
    (F, 3) given); v (V, 3), f (F, 3), adj (F, 3) the face across each edge: `BodyCollider.moved` recomputes them
    every frame of a simulation, in one pass over the faces (the numpy `_set_normals`'s arithmetic: with the
    surface's own angles, vertex normals agree to 1e-15)."""
    nv = v.shape[0]
    for i in range(nv):
        vert_n[i, 0] = 0.0
        vert_n[i, 1] = 0.0
        vert_n[i, 2] = 0.0
    for t in range(f.shape[0]):
        a, b, c = f[t, 0], f[t, 1], f[t, 2]
        e1x, e1y, e1z = v[b, 0] - v[a, 0], v[b, 1] - v[a, 1], v[b, 2] - v[a, 2]
        e2x, e2y, e2z = v[c, 0] - v[a, 0], v[c, 1] - v[a, 1], v[c, 2] - v[a, 2]
        nx, ny, nz = e1y * e2z - e1z * e2y, e1z * e2x - e1x * e2z, e1x * e2y - e1y * e2x
        ln = math.sqrt(nx * nx + ny * ny + nz * nz)
        if ln > 0.0:
            nx, ny, nz = nx / ln, ny / ln, nz / ln
        else:
            nx, ny, nz = 0.0, 0.0, 0.0
        face_n[t, 0], face_n[t, 1], face_n[t, 2] = nx, ny, nz
        for k in range(3):  # each corner's angle weights the face's normal at its vertex
            p = f[t, k]
            ang = angles[t, k]
            vert_n[p, 0] += nx * ang
            vert_n[p, 1] += ny * ang
            vert_n[p, 2] += nz * ang
    for t in range(f.shape[0]):
        for k in range(3):
            o = adj[t, k]
            ex, ey, ez = face_n[t, 0] + face_n[o, 0], face_n[t, 1] + face_n[o, 1], face_n[t, 2] + face_n[o, 2]
            le = max(math.sqrt(ex * ex + ey * ey + ez * ez), 1e-300)
            edge_n[t, k, 0], edge_n[t, k, 1], edge_n[t, k, 2] = ex / le, ey / le, ez / le
    for i in range(nv):
        ln = max(math.sqrt(vert_n[i, 0] ** 2 + vert_n[i, 1] ** 2 + vert_n[i, 2] ** 2), 1e-300)
        vert_n[i, 0] /= ln
        vert_n[i, 1] /= ln
        vert_n[i, 2] /= ln
