"""numba kernels of the relaxation (private: call them through `kitsuke.cloth.relax`).

Each kernel takes contiguous arrays, inputs first and preallocated outputs last, and allocates nothing. Per-element
loops that write only their own element run in `prange`; scatter-adds are avoided by computing per-triangle and
per-hinge results first and gathering them per vertex through CSR arrays. Plain-numpy references live in
tests/cloth/reference.py.
"""

from __future__ import annotations

import math
import os

from numba import njit, prange

#: Compile the per-element kernels for several threads (numba parallel=True). Benchmarked in bench_cloth.py.
PARALLEL = os.environ.get("KITSUKE_NUMBA_PARALLEL", "1") != "0"

#: Squared lengths below this (m^2) count as zero: a triangle or hinge this small has no usable direction.
TINY2 = 1e-24


@njit(cache=True, parallel=PARALLEL)
def reference_normals(pos, faces, face_adj, face_adj_sign, face_active, unflip, out_normals, out_ref, out_flipped):
    """Per face: its unit normal (out_normals (F, 3)), the normal its shape-matching goal should have (out_ref) and
    whether it is flipped (out_flipped (F,) uint8).

    A face is flipped when the sum of its active edge neighbours' unit normals (each turned to agree with this
    face's winding) points against its own normal, or when it has collapsed to no area; then (if `unflip`) its
    goal is laid in the plane facing the neighbours' way, which opens the fold.
    """
    nf = faces.shape[0]
    for t in prange(nf):
        a, b, c = faces[t, 0], faces[t, 1], faces[t, 2]
        ux, uy, uz = pos[b, 0] - pos[a, 0], pos[b, 1] - pos[a, 1], pos[b, 2] - pos[a, 2]
        vx, vy, vz = pos[c, 0] - pos[a, 0], pos[c, 1] - pos[a, 1], pos[c, 2] - pos[a, 2]
        nx, ny, nz = uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx
        n2 = nx * nx + ny * ny + nz * nz
        if n2 > TINY2:
            inv = 1.0 / math.sqrt(n2)
            out_normals[t, 0], out_normals[t, 1], out_normals[t, 2] = nx * inv, ny * inv, nz * inv
        else:
            out_normals[t, 0], out_normals[t, 1], out_normals[t, 2] = 0.0, 0.0, 0.0
    for t in prange(nf):
        nx, ny, nz = out_normals[t, 0], out_normals[t, 1], out_normals[t, 2]
        out_ref[t, 0], out_ref[t, 1], out_ref[t, 2] = nx, ny, nz
        out_flipped[t] = 0
        if not face_active[t]:
            continue
        mx, my, mz = 0.0, 0.0, 0.0
        for k in range(3):
            g = face_adj[t, k]
            if g >= 0 and face_active[g]:
                s = face_adj_sign[t, k]
                mx += s * out_normals[g, 0]
                my += s * out_normals[g, 1]
                mz += s * out_normals[g, 2]
        m2 = mx * mx + my * my + mz * mz
        collapsed = nx * nx + ny * ny + nz * nz < 0.5
        if m2 > 1e-12 and (collapsed or nx * mx + ny * my + nz * mz < 0.0):
            out_flipped[t] = 1
            if unflip:
                inv = 1.0 / math.sqrt(m2)
                out_ref[t, 0], out_ref[t, 1], out_ref[t, 2] = mx * inv, my * inv, mz * inv
        elif collapsed:
            out_flipped[t] = 1
            # No usable neighbour either: any normal perpendicular to the longest edge.
            a, b = faces[t, 0], faces[t, 1]
            ex, ey, ez = pos[b, 0] - pos[a, 0], pos[b, 1] - pos[a, 1], pos[b, 2] - pos[a, 2]
            if abs(ex) < 0.9 * math.sqrt(ex * ex + ey * ey + ez * ez + 1e-300):
                px, py, pz = 0.0, -ez, ey  # e x (1, 0, 0)
            else:
                px, py, pz = ez, 0.0, -ex  # e x (0, 1, 0)
            p2 = px * px + py * py + pz * pz
            if p2 > 0.0:
                inv = 1.0 / math.sqrt(p2)
                out_ref[t, 0], out_ref[t, 1], out_ref[t, 2] = px * inv, py * inv, pz * inv
            else:
                out_ref[t, 0], out_ref[t, 1], out_ref[t, 2] = 0.0, 1.0, 0.0


@njit(cache=True, parallel=PARALLEL)
def shape_match_goals(pos, faces, rest_corners, ref, face_active, out_goals):
    """Per face: where its three corners should be (out_goals (F, 3, 3)): the rest triangle, rotated to fit the
    current one best (least squares over the corners), in the plane through the current centroid with normal `ref`.
    """
    nf = faces.shape[0]
    for t in prange(nf):
        if not face_active[t]:
            continue
        i0, i1, i2 = faces[t, 0], faces[t, 1], faces[t, 2]
        cx = (pos[i0, 0] + pos[i1, 0] + pos[i2, 0]) / 3.0
        cy = (pos[i0, 1] + pos[i1, 1] + pos[i2, 1]) / 3.0
        cz = (pos[i0, 2] + pos[i1, 2] + pos[i2, 2]) / 3.0
        nx, ny, nz = ref[t, 0], ref[t, 1], ref[t, 2]
        # In-plane frame: t1 along the first edge projected into the plane, t2 = n x t1.
        t1x, t1y, t1z = 0.0, 0.0, 0.0
        for k in range(3):
            ia, ib = faces[t, k], faces[t, (k + 1) % 3]
            ex, ey, ez = pos[ib, 0] - pos[ia, 0], pos[ib, 1] - pos[ia, 1], pos[ib, 2] - pos[ia, 2]
            d = ex * nx + ey * ny + ez * nz
            t1x, t1y, t1z = ex - d * nx, ey - d * ny, ez - d * nz
            if t1x * t1x + t1y * t1y + t1z * t1z > TINY2:
                break
        l2 = t1x * t1x + t1y * t1y + t1z * t1z
        if l2 <= TINY2:  # all corners on one point: any in-plane direction
            if abs(nx) < 0.9:
                t1x, t1y, t1z = 0.0, nz, -ny
            else:
                t1x, t1y, t1z = -nz, 0.0, nx
            l2 = t1x * t1x + t1y * t1y + t1z * t1z
        inv = 1.0 / math.sqrt(l2)
        t1x, t1y, t1z = t1x * inv, t1y * inv, t1z * inv
        t2x, t2y, t2z = ny * t1z - nz * t1y, nz * t1x - nx * t1z, nx * t1y - ny * t1x
        qcx = (rest_corners[t, 0, 0] + rest_corners[t, 1, 0] + rest_corners[t, 2, 0]) / 3.0
        qcy = (rest_corners[t, 0, 1] + rest_corners[t, 1, 1] + rest_corners[t, 2, 1]) / 3.0
        sc, ss = 0.0, 0.0
        for k in range(3):
            i = faces[t, k]
            dx, dy, dz = pos[i, 0] - cx, pos[i, 1] - cy, pos[i, 2] - cz
            yx = dx * t1x + dy * t1y + dz * t1z
            yy = dx * t2x + dy * t2y + dz * t2z
            qx, qy = rest_corners[t, k, 0] - qcx, rest_corners[t, k, 1] - qcy
            sc += qx * yx + qy * yy
            ss += qx * yy - qy * yx
        h = math.sqrt(sc * sc + ss * ss)
        if h > 0.0:
            co, si = sc / h, ss / h
        else:
            co, si = 1.0, 0.0
        for k in range(3):
            qx, qy = rest_corners[t, k, 0] - qcx, rest_corners[t, k, 1] - qcy
            rx, ry = co * qx - si * qy, si * qx + co * qy
            out_goals[t, k, 0] = cx + rx * t1x + ry * t2x
            out_goals[t, k, 1] = cy + rx * t1y + ry * t2y
            out_goals[t, k, 2] = cz + rx * t1z + ry * t2z


@njit(cache=True, parallel=PARALLEL)
def hinge_deltas(pos, hinges, hinge_faces, face_active, out_delta):
    """Per hinge (a, b, c, d): the moves (out_delta (H, 4, 3)) that turn its two wings about the edge a-b until
    they are flat (dihedral angle 180°), each wing keeping its distance from the edge; a and b take the opposite of
    the wings' mean move, so the hinge's centre stays put. Zero for inactive, degenerate or fully folded hinges.
    """
    nh = hinges.shape[0]
    for h in prange(nh):
        for s in range(4):
            out_delta[h, s, 0] = 0.0
            out_delta[h, s, 1] = 0.0
            out_delta[h, s, 2] = 0.0
        if not (face_active[hinge_faces[h, 0]] and face_active[hinge_faces[h, 1]]):
            continue
        a, b, c, d = hinges[h, 0], hinges[h, 1], hinges[h, 2], hinges[h, 3]
        ex, ey, ez = pos[b, 0] - pos[a, 0], pos[b, 1] - pos[a, 1], pos[b, 2] - pos[a, 2]
        e2 = ex * ex + ey * ey + ez * ez
        if e2 <= TINY2:
            continue
        inv = 1.0 / math.sqrt(e2)
        ex, ey, ez = ex * inv, ey * inv, ez * inv
        # Components of c - a and d - a perpendicular to the edge.
        cx, cy, cz = pos[c, 0] - pos[a, 0], pos[c, 1] - pos[a, 1], pos[c, 2] - pos[a, 2]
        tc = cx * ex + cy * ey + cz * ez
        cx, cy, cz = cx - tc * ex, cy - tc * ey, cz - tc * ez
        dx, dy, dz = pos[d, 0] - pos[a, 0], pos[d, 1] - pos[a, 1], pos[d, 2] - pos[a, 2]
        td = dx * ex + dy * ey + dz * ez
        dx, dy, dz = dx - td * ex, dy - td * ey, dz - td * ez
        lc = math.sqrt(cx * cx + cy * cy + cz * cz)
        ld = math.sqrt(dx * dx + dy * dy + dz * dz)
        if lc * lc <= TINY2 or ld * ld <= TINY2:
            continue
        ux, uy, uz = cx / lc, cy / lc, cz / lc
        vx, vy, vz = dx / ld, dy / ld, dz / ld
        if ux * vx + uy * vy + uz * vz < -1.0 + 1e-12:
            continue  # already flat
        fx, fy, fz = ux - vx, uy - vy, uz - vz
        f2 = fx * fx + fy * fy + fz * fz
        if f2 <= 1e-12:
            continue  # folded shut: no side to open to (un-flipping handles it)
        inv = 1.0 / math.sqrt(f2)
        fx, fy, fz = fx * inv, fy * inv, fz * inv
        # Flat targets: c along +f, d along -f, same distance from the edge.
        dcx, dcy, dcz = lc * fx - cx, lc * fy - cy, lc * fz - cz
        ddx, ddy, ddz = -ld * fx - dx, -ld * fy - dy, -ld * fz - dz
        out_delta[h, 2, 0], out_delta[h, 2, 1], out_delta[h, 2, 2] = dcx, dcy, dcz
        out_delta[h, 3, 0], out_delta[h, 3, 1], out_delta[h, 3, 2] = ddx, ddy, ddz
        mx, my, mz = -0.5 * (dcx + ddx), -0.5 * (dcy + ddy), -0.5 * (dcz + ddz)
        out_delta[h, 0, 0], out_delta[h, 0, 1], out_delta[h, 0, 2] = mx, my, mz
        out_delta[h, 1, 0], out_delta[h, 1, 1], out_delta[h, 1, 2] = mx, my, mz


@njit(cache=True, parallel=PARALLEL)
def gather_moves(
    pos,
    goals,
    hinge_delta,
    vc_ptr,
    vc,
    vh_ptr,
    vh,
    face_active,
    hinge_faces,
    pinned,
    contact_face,
    contact_distance,
    contact_normal,
    stretch,
    bend,
    gravity,
    friction,
    contact_distance_m,
    max_step,
    out_pos,
    out_step,
):
    """Per vertex: move = stretch * mean(goal - position over its active triangles) + bend * mean(hinge moves over
    its active hinges) + gravity (downward, metres); where the vertex touches the body and the move presses into
    it, its tangential part shrinks by `friction` times the pressing part (Coulomb); clamped to `max_step`
    metres. Pinned vertices and vertices with no active triangle stay.
    Writes the new positions (out_pos (V, 3)) and the length of each move (out_step (V,)).
    """
    nv = pos.shape[0]
    for i in prange(nv):
        px, py, pz = pos[i, 0], pos[i, 1], pos[i, 2]
        out_pos[i, 0], out_pos[i, 1], out_pos[i, 2] = px, py, pz
        out_step[i] = 0.0
        if pinned[i]:
            continue
        sx, sy, sz, n = 0.0, 0.0, 0.0, 0
        for j in range(vc_ptr[i], vc_ptr[i + 1]):
            cor = vc[j]
            t, k = cor // 3, cor % 3
            if face_active[t]:
                sx += goals[t, k, 0] - px
                sy += goals[t, k, 1] - py
                sz += goals[t, k, 2] - pz
                n += 1
        if n == 0:
            continue
        mx, my, mz = stretch * sx / n, stretch * sy / n, stretch * sz / n
        bx, by, bz, m = 0.0, 0.0, 0.0, 0
        for j in range(vh_ptr[i], vh_ptr[i + 1]):
            slot = vh[j]
            h, s = slot // 4, slot % 4
            if face_active[hinge_faces[h, 0]] and face_active[hinge_faces[h, 1]]:
                bx += hinge_delta[h, s, 0]
                by += hinge_delta[h, s, 1]
                bz += hinge_delta[h, s, 2]
                m += 1
        if m > 0:
            mx += bend * bx / m
            my += bend * by / m
            mz += bend * bz / m
        my -= gravity
        if contact_face[i] >= 0 and contact_distance[i] < contact_distance_m and friction > 0.0:
            # Coulomb friction: a move pressing into the body by dn < 0 loses up to friction * |dn| of its
            # tangential part (it sticks when that is all of it); moving away from the body is free.
            nx, ny, nz = contact_normal[i, 0], contact_normal[i, 1], contact_normal[i, 2]
            dn = mx * nx + my * ny + mz * nz
            if dn < 0.0:
                tx, ty, tz = mx - dn * nx, my - dn * ny, mz - dn * nz
                tl = math.sqrt(tx * tx + ty * ty + tz * tz)
                keep = max(0.0, 1.0 - friction * -dn / tl) if tl > 0.0 else 0.0
                mx, my, mz = dn * nx + keep * tx, dn * ny + keep * ty, dn * nz + keep * tz
        step = math.sqrt(mx * mx + my * my + mz * mz)
        if step > max_step:
            f = max_step / step
            mx, my, mz, step = mx * f, my * f, mz * f, max_step
        out_pos[i, 0], out_pos[i, 1], out_pos[i, 2] = px + mx, py + my, pz + mz
        out_step[i] = step


@njit(cache=True)
def support_order(pos, roots, active, by_height, out_order, out_rank):
    """The order in which strain limiting visits the vertices: the supports (`roots` (V,) bool) first, then the
    other `active` vertices from the top down.

    by_height (V,) int64: a permutation of the vertices, re-sorted in place by decreasing height (insertion sort:
    about linear when last iteration's order is passed in, as vertices move little per iteration). Writes
    out_order (roots, then the rest; returns how many) and out_rank (V,) (each vertex's place, -1 if inactive).
    """
    nv = by_height.shape[0]
    for o in range(1, nv):
        v = by_height[o]
        y = pos[v, 1]
        k = o - 1
        while k >= 0 and pos[by_height[k], 1] < y:
            by_height[k + 1] = by_height[k]
            k -= 1
        by_height[k + 1] = v
    n = 0
    for o in range(nv):
        v = by_height[o]
        out_rank[v] = -1
        if roots[v] and active[v]:
            out_rank[v] = n
            out_order[n] = v
            n += 1
    for o in range(nv):
        v = by_height[o]
        if active[v] and not roots[v]:
            out_rank[v] = n
            out_order[n] = v
            n += 1
    return n


@njit(cache=True)
def limit_strain(order, n_order, rank, movable, adj_ptr, adj, adj_edge, rest_lengths, max_stretch, pos):
    """Strain limiting from the supports and the top down (Gauss-Seidel, in place on pos (V, 3)): in
    `support_order`, each movable vertex is pulled towards each neighbour visited before it until their edge is
    at most (1 + max_stretch) times its rest length. Cloth thus hangs from its supports and from what is above
    it however long the chain of vertices — Jacobi averaging alone lets the accumulated gravity moves stretch a
    chain in proportion to its length. Every edge is limited once, by moving its later end.
    """
    for o in range(n_order):
        i = order[o]
        if not movable[i]:
            continue
        for j in range(adj_ptr[i], adj_ptr[i + 1]):
            k = adj[j]
            rk = rank[k]
            if rk < 0 or rk >= o:
                continue
            lim = (1.0 + max_stretch) * rest_lengths[adj_edge[j]]
            dx, dy, dz = pos[i, 0] - pos[k, 0], pos[i, 1] - pos[k, 1], pos[i, 2] - pos[k, 2]
            d = math.sqrt(dx * dx + dy * dy + dz * dz)
            if d > lim:
                f = lim / d
                pos[i, 0] = pos[k, 0] + dx * f
                pos[i, 1] = pos[k, 1] + dy * f
                pos[i, 2] = pos[k, 2] + dz * f


@njit(cache=True)
def _project_edge(pos, a, b, rest, movable, omega, band):
    """Move the movable ends of edge a-b (in place on pos) along it to its rest length `rest` (or the nearer end of
    its band), times `omega`; returns the error corrected, metres (0.0: left alone)."""
    wa = 1.0 if movable[a] else 0.0
    wb = 1.0 if movable[b] else 0.0
    if wa + wb == 0.0:
        return 0.0
    dx, dy, dz = pos[b, 0] - pos[a, 0], pos[b, 1] - pos[a, 1], pos[b, 2] - pos[a, 2]
    d = math.sqrt(dx * dx + dy * dy + dz * dz)
    if d * d < TINY2:
        return 0.0
    err = d - rest
    slack = band * rest
    if err > slack:
        err -= slack
    elif err < -slack:
        err += slack
    else:
        return 0.0
    f = omega * err / (d * (wa + wb))
    pos[a, 0] += wa * f * dx
    pos[a, 1] += wa * f * dy
    pos[a, 2] += wa * f * dz
    pos[b, 0] -= wb * f * dx
    pos[b, 1] -= wb * f * dy
    pos[b, 2] -= wb * f * dz
    return err


@njit(cache=True)
def project_lengths(pos, edges, rest_lengths, movable, order, omega, band):
    """One Gauss-Seidel sweep (in place on pos (V, 3)): each edge in `order` moves its movable ends, half each
    (all of it for one movable end), along the edge until it has its rest length, times `omega` (1: exactly;
    1 < omega < 2: over-relaxed, past it). With `band` > 0 (a strain, e.g. 0.045) an edge within band * rest of
    its rest length is left alone and one outside is moved to the nearer end of the band instead (a strain
    limit). Returns the largest length error met in the sweep, metres (before its correction; beyond the band).
    Sequential on purpose: each projection sees the previous ones, which is what makes a sweep converge where a
    Jacobi average would cancel itself out.
    """
    worst = 0.0
    for o in range(len(order)):
        e = order[o]
        err = _project_edge(pos, edges[e, 0], edges[e, 1], rest_lengths[e], movable, omega, band)
        worst = max(worst, abs(err))
    return worst


@njit(cache=True)
def project_band(pos, edges, rest_lengths, movable, order, band, moved, seen, clock):
    """`project_lengths` with omega 1 and a band > 0 (a strain limit), skipping every edge whose ends have not moved
    since it was last met: it was within its band then and still is, so the sweep is the same to the last bit.
    A strain limit moves a few edges of thousands per sweep, so most sweeps skip most of them.

    moved (V,) int64: when each vertex last moved; seen (E,) int64: when each edge was last met (-1: never);
    clock (1,) int64: the time now. All in place; a vertex moved outside the kernels (collision) must get
    moved[v] = clock[0] + 1 and the clock that value.
    """
    worst = 0.0
    t = clock[0]
    for o in range(len(order)):
        e = order[o]
        a, b = edges[e, 0], edges[e, 1]
        if moved[a] <= seen[e] and moved[b] <= seen[e]:
            continue
        t += 1
        seen[e] = t
        err = _project_edge(pos, a, b, rest_lengths[e], movable, 1.0, band)
        if err == 0.0:
            continue
        worst = max(worst, abs(err))
        t += 1
        if movable[a]:
            moved[a] = t
        if movable[b]:
            moved[b] = t
    clock[0] = t
    return worst


#: Segments either side of a tether point's last nearest one that `project_tethers` searches while its cache holds.
TETHER_WINDOW = 4


@njit(cache=True)
def _segment_nearest(px, py, pz, line_points, j, last):
    """Nearest point to p on segment j of a polyline whose last point is `last` (a one-point polyline: that
    point). Returns (squared distance, x, y, z)."""
    ax, ay, az = line_points[j, 0], line_points[j, 1], line_points[j, 2]
    t = 0.0
    ex = ey = ez = 0.0
    if j < last:
        ex, ey, ez = line_points[j + 1, 0] - ax, line_points[j + 1, 1] - ay, line_points[j + 1, 2] - az
        ee = ex * ex + ey * ey + ez * ez
        if ee > TINY2:
            t = min(1.0, max(0.0, ((px - ax) * ex + (py - ay) * ey + (pz - az) * ez) / ee))
    cx, cy, cz = ax + t * ex, ay + t * ey, az + t * ez
    return (px - cx) ** 2 + (py - cy) ** 2 + (pz - cz) ** 2, cx, cy, cz


@njit(cache=True)
def project_tethers(pos, tri, bary, movable, line_points, line_start, line_of, reach, seg, second, snap, stamps):
    """One sweep of tethers (in place on pos (V, 3)): each cloth point p = sum_k bary[i, k] * pos[tri[i, k]]
    farther than `reach` metres from its polyline (points line_points[line_start[l]:line_start[l + 1]], l =
    line_of[i]) is pulled straight towards the polyline's nearest point until it is `reach` away, its vertices
    moving in proportion to their barycentric weight (the least-norm move that does it). A point with a vertex
    that may not move is left to it: moving only the others could take a vertex of small weight far (by the
    distance over its weight). Returns the largest distance beyond `reach` met in the sweep, metres (before the
    correction), over the points it may move.

    seg (n,) int64, second (n,) float64, snap (n, 3) float64: a cache of each point's nearest segment (-1: none
    yet), updated in place. When a point was last searched at `snap`, every segment more than TETHER_WINDOW
    segments from the nearest was at least `second` metres away, so it is still at least `second - |p - snap|`
    away now: while the best segment of that window is nearer than that, it is the nearest and only the window
    is searched (exact, not a heuristic; the cloth moves far less per sweep than that). Same result as a full
    search every time.

    stamps : None, or (moved (V,) int64, seen (n,) int64, clock (1,) int64) as in `project_band`: a point none
    of whose vertices moved since it was last met is skipped (it was within reach then, or pulled to it).
    """
    worst = 0.0
    t = 0
    if stamps is not None:
        t = stamps[2][0]
    for i in range(tri.shape[0]):
        if not (movable[tri[i, 0]] and movable[tri[i, 1]] and movable[tri[i, 2]]):
            continue
        if stamps is not None:
            vmoved, seen = stamps[0], stamps[1]
            if vmoved[tri[i, 0]] <= seen[i] and vmoved[tri[i, 1]] <= seen[i] and vmoved[tri[i, 2]] <= seen[i]:
                continue
            t += 1
            seen[i] = t
        px = py = pz = 0.0
        for k in range(3):
            v = tri[i, k]
            px += bary[i, k] * pos[v, 0]
            py += bary[i, k] * pos[v, 1]
            pz += bary[i, k] * pos[v, 2]
        l = line_of[i]
        first, last = line_start[l], line_start[l + 1] - 1
        stop = max(last, first + 1)  # segments first..stop-1 (one for a one-point polyline)
        found = False
        best = qx = qy = qz = 0.0
        if seg[i] >= 0:
            best = math.inf
            for j in range(max(first, seg[i] - TETHER_WINDOW), min(stop, seg[i] + TETHER_WINDOW + 1)):
                d2, cx, cy, cz = _segment_nearest(px, py, pz, line_points, j, last)
                if d2 < best:
                    best, qx, qy, qz = d2, cx, cy, cz
            moved = math.sqrt((px - snap[i, 0]) ** 2 + (py - snap[i, 1]) ** 2 + (pz - snap[i, 2]) ** 2)
            found = math.sqrt(best) < second[i] - moved
        if not found:
            best = math.inf
            for j in range(first, stop):
                d2, cx, cy, cz = _segment_nearest(px, py, pz, line_points, j, last)
                if d2 < best:
                    best, qx, qy, qz = d2, cx, cy, cz
                    seg[i] = j
            outside = math.inf
            for j in range(first, stop):
                if abs(j - seg[i]) > TETHER_WINDOW:
                    outside = min(outside, _segment_nearest(px, py, pz, line_points, j, last)[0])
            second[i] = math.sqrt(outside)
            snap[i, 0], snap[i, 1], snap[i, 2] = px, py, pz
        d = math.sqrt(best)
        over = d - reach
        if over <= 0.0:
            continue
        worst = max(worst, over)
        w2 = bary[i, 0] * bary[i, 0] + bary[i, 1] * bary[i, 1] + bary[i, 2] * bary[i, 2]
        f = over / (d * w2)
        t += 1
        for k in range(3):
            v = tri[i, k]
            s = f * bary[i, k]
            pos[v, 0] += s * (qx - px)
            pos[v, 1] += s * (qy - py)
            pos[v, 2] += s * (qz - pz)
            if stamps is not None:
                stamps[0][v] = t
    if stamps is not None:
        stamps[2][0] = t
    return worst


def set_parallel(parallel: bool) -> None:
    """Recompile the per-element kernels with or without threads (for benchmarks; not cached)."""
    g = globals()
    for name in ("reference_normals", "shape_match_goals", "hinge_deltas", "gather_moves"):
        g[name] = njit(parallel=parallel)(g[name].py_func)
