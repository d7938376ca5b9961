"""numba kernels of the drag along the body (private: use `kitsuke.dressing.drag`).

- `trace_points`: move points along a triangle mesh surface, each by a tangent vector, on the straight line of the
  unfolded triangles (a discrete geodesic: the direction keeps its angle to every edge it crosses).
- `drag_moves`: every cloth vertex moves by its weighted drag vector; near the body its foot (its nearest body
  point) slides along the surface by the same vector, and where the body curves towards the vertex it is lifted
  back to its height above the foot.

Body arrays: bv (Vb, 3) vertices, bf (Fb, 3) faces, face_adj (Fb, 3) the face across each local edge k
(corners k, k+1), face_n (Fb, 3) unit face normals, vert_n (Vb, 3) unit vertex normals.
"""

from __future__ import annotations

import math

from numba import njit, prange

from ..cloth._collide_kernels import PARALLEL

#: A direction component below this (relative to a unit direction) counts as zero.
EPS = 1e-12


@njit(cache=True)
def _point(bv, bf, f, b0, b1, b2):
    i0, i1, i2 = bf[f, 0], bf[f, 1], bf[f, 2]
    return (
        b0 * bv[i0, 0] + b1 * bv[i1, 0] + b2 * bv[i2, 0],
        b0 * bv[i0, 1] + b1 * bv[i1, 1] + b2 * bv[i2, 1],
        b0 * bv[i0, 2] + b1 * bv[i1, 2] + b2 * bv[i2, 2],
    )


@njit(cache=True)
def _interp_unit(vals, bf, f, b0, b1, b2):
    """Barycentric interpolation of per-vertex vectors vals (Vb, 3) in face f, normalised (0 if it vanishes)."""
    i0, i1, i2 = bf[f, 0], bf[f, 1], bf[f, 2]
    x = b0 * vals[i0, 0] + b1 * vals[i1, 0] + b2 * vals[i2, 0]
    y = b0 * vals[i0, 1] + b1 * vals[i1, 1] + b2 * vals[i2, 1]
    z = b0 * vals[i0, 2] + b1 * vals[i1, 2] + b2 * vals[i2, 2]
    n = math.sqrt(x * x + y * y + z * z)
    if n > EPS:
        return x / n, y / n, z / n
    return 0.0, 0.0, 0.0


@njit(cache=True)
def _pick(k, x0, x1, x2):
    return x0 if k == 0 else (x1 if k == 1 else x2)


@njit(cache=True)
def trace_one(bv, bf, face_adj, face_n, f, b0, b1, b2, tx, ty, tz, max_cross):
    """Move the surface point (face f, barycentrics b) by the vector t along the surface.

    t is projected into face f's plane (the part along the normal is dropped): the point travels the
    projection's length (metres) on the straight line of the unfolded triangles. Crossing an edge, the direction
    turns about it from one face's plane into the next (its angle to the edge stays). Stops early at a boundary
    edge, a degenerate face or after `max_cross` crossings. Returns (face, b0, b1, b2, distance travelled).
    """
    length = math.sqrt(tx * tx + ty * ty + tz * tz)
    if length <= 0.0:
        return f, b0, b1, b2, 0.0
    nx, ny, nz = face_n[f, 0], face_n[f, 1], face_n[f, 2]
    dn = tx * nx + ty * ny + tz * nz
    dx, dy, dz = tx - dn * nx, ty - dn * ny, tz - dn * nz
    dl = math.sqrt(dx * dx + dy * dy + dz * dz)
    if dl <= EPS * length:
        return f, b0, b1, b2, 0.0
    dx, dy, dz = dx / dl, dy / dl, dz / dl
    length = dl
    left = length
    for _ in range(max_cross + 1):
        i0, i1, i2 = bf[f, 0], bf[f, 1], bf[f, 2]
        e1x, e1y, e1z = bv[i1, 0] - bv[i0, 0], bv[i1, 1] - bv[i0, 1], bv[i1, 2] - bv[i0, 2]
        e2x, e2y, e2z = bv[i2, 0] - bv[i0, 0], bv[i2, 1] - bv[i0, 1], bv[i2, 2] - bv[i0, 2]
        g11 = e1x * e1x + e1y * e1y + e1z * e1z
        g12 = e1x * e2x + e1y * e2y + e1z * e2z
        g22 = e2x * e2x + e2y * e2y + e2z * e2z
        det = g11 * g22 - g12 * g12
        if det <= 1e-30 * g11 * g22 or det <= 0.0:
            break
        r1 = dx * e1x + dy * e1y + dz * e1z
        r2 = dx * e2x + dy * e2y + dz * e2z
        # Barycentric rates along the unit direction: d = db1 e1 + db2 e2, db0 = -db1 - db2.
        db1 = (g22 * r1 - g12 * r2) / det
        db2 = (g11 * r2 - g12 * r1) / det
        db0 = -db1 - db2
        # The first barycentric to reach 0 says which edge the line leaves by.
        s, k = math.inf, -1
        if db0 < 0.0:
            s, k = max(b0, 0.0) / -db0, 0
        if db1 < 0.0 and max(b1, 0.0) / -db1 < s:
            s, k = max(b1, 0.0) / -db1, 1
        if db2 < 0.0 and max(b2, 0.0) / -db2 < s:
            s, k = max(b2, 0.0) / -db2, 2
        if k < 0 or s >= left:
            b0, b1, b2 = b0 + left * db0, b1 + left * db1, b2 + left * db2
            left = 0.0
            break
        b0, b1, b2 = b0 + s * db0, b1 + s * db1, b2 + s * db2
        left -= s
        e = (k + 1) % 3  # the local edge opposite corner k: corners e, e + 1
        g = face_adj[f, e]
        if g < 0:
            break
        va, vb = bf[f, e], bf[f, (e + 1) % 3]
        wa, wb = _pick(e, b0, b1, b2), _pick((e + 1) % 3, b0, b1, b2)
        wsum = wa + wb
        wa, wb = (wa / wsum, wb / wsum) if wsum > 0.0 else (0.5, 0.5)
        # Turn the direction about the shared edge from this face's plane into the next one's.
        ux, uy, uz = bv[vb, 0] - bv[va, 0], bv[vb, 1] - bv[va, 1], bv[vb, 2] - bv[va, 2]
        ul = math.sqrt(ux * ux + uy * uy + uz * uz)
        ux, uy, uz = ux / ul, uy / ul, uz / ul
        along = dx * ux + dy * uy + dz * uz
        m1x, m1y, m1z = ny * uz - nz * uy, nz * ux - nx * uz, nx * uy - ny * ux
        across = dx * m1x + dy * m1y + dz * m1z
        nx, ny, nz = face_n[g, 0], face_n[g, 1], face_n[g, 2]
        m2x, m2y, m2z = ny * uz - nz * uy, nz * ux - nx * uz, nx * uy - ny * ux
        dx, dy, dz = along * ux + across * m2x, along * uy + across * m2y, along * uz + across * m2z
        dl = math.sqrt(dx * dx + dy * dy + dz * dz)
        if dl <= EPS:
            break
        dx, dy, dz = dx / dl, dy / dl, dz / dl
        j0, j1, j2 = bf[g, 0], bf[g, 1], bf[g, 2]
        b0 = wa if j0 == va else (wb if j0 == vb else 0.0)
        b1 = wa if j1 == va else (wb if j1 == vb else 0.0)
        b2 = wa if j2 == va else (wb if j2 == vb else 0.0)
        f = g
    # Round-off: keep the barycentrics a convex combination.
    b0, b1, b2 = max(b0, 0.0), max(b1, 0.0), max(b2, 0.0)
    s = b0 + b1 + b2
    if s <= 0.0:
        return f, 1.0, 0.0, 0.0, length - left
    return f, b0 / s, b1 / s, b2 / s, length - left


@njit(cache=True, parallel=PARALLEL)
def trace_points(bv, bf, face_adj, face_n, faces, bary, vectors, max_cross, out_face, out_bary, out_point, out_dist):
    """`trace_one` for n points: faces (n,), bary (n, 3), vectors (n, 3) metres -> out_face (n,), out_bary
    (n, 3), out_point (n, 3) metres, out_dist (n,) metres travelled."""
    for i in prange(faces.shape[0]):
        f, b0, b1, b2, d = trace_one(
            bv, bf, face_adj, face_n, faces[i], bary[i, 0], bary[i, 1], bary[i, 2],
            vectors[i, 0], vectors[i, 1], vectors[i, 2], max_cross,
        )  # fmt: skip
        out_face[i] = f
        out_bary[i, 0], out_bary[i, 1], out_bary[i, 2] = b0, b1, b2
        out_point[i, 0], out_point[i, 1], out_point[i, 2] = _point(bv, bf, f, b0, b1, b2)
        out_dist[i] = d


@njit(cache=True, parallel=PARALLEL)
def drag_moves(
    pos,
    weight,
    follow,
    vec,
    bv,
    bf,
    face_adj,
    face_n,
    vert_n,
    max_cross,
    foot_face,
    foot_bary,
    foot_point,
    out_move,
):
    """Move every vertex by its weighted drag vector (in place on pos), along the body where it is near it.

    pos (V, 3) metres; weight (V,) in [0, 1]; follow (V,) in [0, 1]: how much the vertex keeps to the body;
    vec (V, 3) each vertex's drag vector (metres). Every vertex is translated by weight * vec. A vertex that
    keeps to the body also moves its foot (foot_face (V,), foot_bary (V, 3), foot_point (V, 3): in now, out
    after the move) that far along the surface, and where the translation brought it closer to the body than it
    was (the body rises towards it), it is lifted back to its height above the new foot, along the normal there
    (times follow); where the body falls away beneath it, it goes straight on and bridges the gap, as cloth
    does. out_move (V, 3): the move of each vertex, metres.
    """
    for i in prange(pos.shape[0]):
        w = weight[i]
        s = follow[i]
        mx, my, mz = w * vec[i, 0], w * vec[i, 1], w * vec[i, 2]
        f = foot_face[i]
        if w <= 0.0:
            mx, my, mz = 0.0, 0.0, 0.0
        elif s > 0.0 and f >= 0:
            b0, b1, b2 = foot_bary[i, 0], foot_bary[i, 1], foot_bary[i, 2]
            nx, ny, nz = _interp_unit(vert_n, bf, f, b0, b1, b2)
            ox, oy, oz = pos[i, 0] - foot_point[i, 0], pos[i, 1] - foot_point[i, 1], pos[i, 2] - foot_point[i, 2]
            h = ox * nx + oy * ny + oz * nz
            g, c0, c1, c2, _ = trace_one(bv, bf, face_adj, face_n, f, b0, b1, b2, mx, my, mz, max_cross)
            px, py, pz = _point(bv, bf, g, c0, c1, c2)
            qx, qy, qz = _interp_unit(vert_n, bf, g, c0, c1, c2)
            # Height of the translated vertex above the new foot's tangent plane.
            hn = (pos[i, 0] + mx - px) * qx + (pos[i, 1] + my - py) * qy + (pos[i, 2] + mz - pz) * qz
            if hn < h:
                lift = s * (h - hn)
                mx, my, mz = mx + lift * qx, my + lift * qy, mz + lift * qz
            foot_face[i] = g
            foot_bary[i, 0], foot_bary[i, 1], foot_bary[i, 2] = c0, c1, c2
            foot_point[i, 0], foot_point[i, 1], foot_point[i, 2] = px, py, pz
        out_move[i, 0], out_move[i, 1], out_move[i, 2] = mx, my, mz
        pos[i, 0] += mx
        pos[i, 1] += my
        pos[i, 2] += mz
