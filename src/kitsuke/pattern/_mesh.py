"""Triangulation of pattern pieces with Shewchuk's Triangle, seam-aware (SPEC §4.2).

How a piece is meshed:

1. Boundary: every edge is resampled into equal arc-length segments of at most the target length h. Both edges of
   a seam get the same count, ceil(longer edge / h), so their vertices pair up one to one.
2. Interior: points of a hexagonal lattice of spacing h (equilateral triangles of side h), keeping those inside the
   piece and farther than 0.6 h from its boundary.
3. Triangle builds the constrained Delaunay triangulation of boundary + lattice with quality refinement
   (`q<min_angle>`: no angle below the minimum), an area cap of 1.5 equilateral triangles of side h (`a`), and
   `Y`: no Steiner points on the boundary, so each edge keeps exactly the vertices of step 1.

The lattice makes nearly all interior triangles equilateral with side h; Triangle only repairs the band next to the
boundary. Faces are counter-clockwise in pattern coordinates (normals along the outer face once placed), reversed
for `flipped` pieces.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field

import numpy as np

from .. import limits
from .._files import write_text_atomic
from ..errors import InputError
from ._layers import LayerRegion, pattern_layers
from ._types import EdgeRef, Pattern
from ._validate import check_pattern

#: Interior lattice points closer than this many target lengths to the boundary are dropped.
LATTICE_MARGIN = 0.6
#: Triangle's area cap, in equilateral triangles of side h.
AREA_CAP = 1.5


@dataclass
class PatternMesh:
    """A triangulated pattern: all pieces in one vertex/face array, pieces contiguous, seams not welded.

    Attributes
    ----------
    name : the pattern's name.
    piece_names : (P,) piece names in pattern order.
    vertices_cm : (V, 2) float64, cm, piece-local pattern coordinates (the rest shape, and the UV source).
    positions_m : (V, 3) float64, metres, world frame (Y up, facing +Z): placed with each piece's placement hint;
        pieces without one are laid flat in the z = 0 plane, side by side to the right of x = 1 m.
    faces : (F, 3) int64, counter-clockwise seen from each piece's outer face.
    vertex_piece : (V,) int32, piece index of each vertex.
    piece_vertices : (P, 2) int64, [start, stop) vertex range of each piece.
    piece_faces : (P, 2) int64, [start, stop) face range of each piece.
    edge_vertices : {EdgeRef: (k,) int64} vertex indices along every edge of every piece, from its start to its end.
    seam_vertices : one (k, 2) int64 array per pattern seam: vertex pairs sewn together (a side, b side).
    placed : (P,) bool, whether each piece had a placement hint.
    edge_length_cm : the target edge length, cm.
    layers : the pattern's cloth layers (`meta["layers"]`, see `_layers`), if any.
    """

    name: str
    piece_names: list[str]
    vertices_cm: np.ndarray
    positions_m: np.ndarray
    faces: np.ndarray
    vertex_piece: np.ndarray
    piece_vertices: np.ndarray
    piece_faces: np.ndarray
    edge_vertices: dict[EdgeRef, np.ndarray] = field(repr=False)
    seam_vertices: list[np.ndarray] = field(repr=False)
    placed: np.ndarray = field(repr=False)
    edge_length_cm: float = 1.5
    layers: tuple[LayerRegion, ...] = ()

    @property
    def n_vertices(self) -> int:
        return len(self.vertices_cm)

    @property
    def n_faces(self) -> int:
        return len(self.faces)

    def face_areas_cm2(self) -> np.ndarray:
        """(F,) float64 areas in pattern space, cm^2."""
        t = self.vertices_cm[self.faces]
        d1, d2 = t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]
        return 0.5 * np.abs(d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0])

    def uv(self, tile_cm: tuple[float, float] | None = None) -> np.ndarray:
        """(V, 2) texture coordinates: pattern cm / tile size (REPEAT wrapping, v up; see kitsuke.pattern.texture),
        or pattern metres when `tile_cm` is None (SPEC §3.3's vt)."""
        scale = np.array([100.0, 100.0]) if tile_cm is None else np.asarray(tile_cm, dtype=np.float64)
        return self.vertices_cm / scale

    def to_trimesh(
        self,
        *,
        placed: bool = True,
        texture: np.ndarray | None = None,
        texture_tile_cm: tuple[float, float] | None = None,
    ):
        """The mesh as a `kitsuke.geometry.TriMesh`.

        placed : True: vertices at `positions_m` (around the body); False: flat, pattern coordinates in metres
            (x, y, 0) with pieces side by side as in the picture layout's order.
        texture, texture_tile_cm : a tileable texture and the cm it covers; uv = pattern cm / tile (REPEAT wrap).
            Without a tile size, uv = pattern metres.
        """
        from ..geometry import TriMesh

        verts = self.positions_m if placed else self.flat_positions_m()
        return TriMesh(verts, self.faces, self.uv(texture_tile_cm), self.name, texture)

    def flat_positions_m(self) -> np.ndarray:
        """(V, 3) pattern coordinates in metres, pieces side by side along x with 10 cm gaps, z = 0."""
        out = np.zeros((self.n_vertices, 3))
        x = 0.0
        for s, e in self.piece_vertices:
            v = self.vertices_cm[s:e] / 100.0
            lo, hi = v.min(axis=0), v.max(axis=0)
            out[s:e, :2] = v - lo + [x, 0.0]
            x += float(hi[0] - lo[0]) + 0.1
        return out


def _scanline_inside(poly: np.ndarray, ys: np.ndarray, xs_per_row: list[np.ndarray]) -> list[np.ndarray]:
    """Even-odd inside test of lattice rows: for each row y, a mask over its x values."""
    a, b = poly, np.roll(poly, -1, axis=0)
    out = []
    for y, xs in zip(ys, xs_per_row, strict=True):
        crosses = (a[:, 1] > y) != (b[:, 1] > y)
        ax, ay, bx, by = a[crosses, 0], a[crosses, 1], b[crosses, 0], b[crosses, 1]
        xc = np.sort(ax + (y - ay) * (bx - ax) / (by - ay))
        out.append(np.searchsorted(xc, xs) % 2 == 1)
    return out


def _lattice(boundary: np.ndarray, h: float) -> np.ndarray:
    """Hexagonal lattice points (m, 2) of spacing h inside the polygon, at least LATTICE_MARGIN h from its boundary."""
    lo, hi = boundary.min(axis=0), boundary.max(axis=0)
    dy = h * math.sqrt(3.0) / 2.0
    ys = np.arange(lo[1] + 0.5 * dy, hi[1], dy)
    rows = [np.arange(lo[0] + (0.5 * h if i % 2 else 0.0) + 0.25 * h, hi[0], h) for i in range(len(ys))]
    masks = _scanline_inside(boundary, ys, rows)
    pts = [np.c_[xs[m], np.full(int(m.sum()), y)] for y, xs, m in zip(ys, rows, masks, strict=True)]
    pts = np.concatenate(pts) if pts else np.zeros((0, 2))
    if not len(pts):
        return pts
    # Distance to the boundary from a dense sampling of it (spacing h/8: error below h/100 at the margin).
    d_seg = np.roll(boundary, -1, axis=0) - boundary
    counts = np.maximum(1, np.ceil(np.linalg.norm(d_seg, axis=1) / (h / 8)).astype(np.int64))
    seg_of = np.repeat(np.arange(len(boundary)), counts)
    frac = (np.arange(counts.sum()) - np.repeat(np.cumsum(counts) - counts, counts)) / counts[seg_of]
    dense = boundary[seg_of] + frac[:, None] * d_seg[seg_of]
    return pts[_farther_than(pts, dense, LATTICE_MARGIN * h)]


def _farther_than(points: np.ndarray, samples: np.ndarray, reach: float) -> np.ndarray:
    """(m,) bool: is each point (m, 2) farther than `reach` from every sample (n, 2)? Exact, on a grid of cells
    `reach` wide: every sample within reach of a point lies in the 3 x 3 cells round the point's cell, so each
    sample is listed in those nine and each point compared with its own cell's list only (numpy alone: importing
    scipy.spatial for a k-d tree took 0.3-0.4 s of every command that meshes a pattern)."""
    far = np.ones(len(points), dtype=bool)
    if not len(points) or not len(samples):
        return far
    origin = np.minimum(points.min(axis=0), samples.min(axis=0)) - reach
    cell_p = np.floor((points - origin) / reach).astype(np.int64)
    cell_s = np.floor((samples - origin) / reach).astype(np.int64)
    width = int(max(cell_p[:, 0].max(), cell_s[:, 0].max())) + 3
    shifts = np.array([(dx, dy) for dx in (-1, 0, 1) for dy in (-1, 0, 1)])
    listed = (cell_s[None, :, :] + shifts[:, None, :]).reshape(-1, 2)  # each sample in the nine cells round it
    key_s = listed[:, 1] * width + listed[:, 0]
    owner = np.tile(np.arange(len(samples)), len(shifts))
    order = np.argsort(key_s, kind="stable")
    key_s, owner = key_s[order], owner[order]
    key_p = cell_p[:, 1] * width + cell_p[:, 0]
    start, stop = np.searchsorted(key_s, key_p, side="left"), np.searchsorted(key_s, key_p, side="right")
    count = stop - start
    near = np.flatnonzero(count)
    if not len(near):
        return far
    pair_point = np.repeat(near, count[near])
    offsets = np.arange(len(pair_point)) - np.repeat(np.cumsum(count[near]) - count[near], count[near])
    pair_sample = owner[np.repeat(start[near], count[near]) + offsets]
    diff = points[pair_point] - samples[pair_sample]
    d = np.sqrt((diff * diff).sum(axis=1))
    nearest = np.full(len(points), np.inf)
    np.minimum.at(nearest, pair_point, d)
    return nearest > reach


def _segments_for(pattern: Pattern, h: float) -> dict[EdgeRef, int]:
    counts: dict[EdgeRef, int] = {}
    for p in pattern.pieces:
        for e, length in enumerate(p.edge_lengths()):
            counts[EdgeRef(p.name, e)] = max(1, math.ceil(length / h - 1e-9))
    for s in pattern.seams:
        longer = max(pattern.edge_length(s.a), pattern.edge_length(s.b))
        n = max(1, math.ceil(longer / h - 1e-9))
        counts[s.a] = counts[s.b] = n
    return counts


def mesh_pattern(pattern: Pattern, *, edge_length: float = 1.5, min_angle: float = 25.0) -> PatternMesh:
    """Triangulate every piece of a (valid) pattern at a target edge length (cm) and minimum angle (degrees).

    Raises InputError for a bad edge length or angle, or a pattern that `validate` reports errors for.
    """
    import triangle

    if not (math.isfinite(edge_length) and edge_length > 0):
        raise InputError(f"edge length must be a positive number of cm, got {edge_length}", "--edge-length")
    if not 0 < min_angle <= 34:
        raise InputError("minimum angle must be in (0, 34] degrees (Triangle's limit for guaranteed termination)")
    check_pattern(pattern)
    extent = max(float(np.ptp(p.bounds, axis=0).max()) for p in pattern.pieces)
    total = sum(p.area for p in pattern.pieces)
    h = float(edge_length)
    # A triangle of edge h covers about 0.433 h²; checked before Triangle allocates anything.
    estimate = total / (0.433 * h * h)
    limits.check(
        "triangles",
        estimate,
        f"meshing {total / 1e4:,.4g} m² of cloth at edge length {h:g} cm would make about {estimate:,.0f} triangles "
        "(a longer --edge-length makes fewer)",
        pattern.source or "--edge-length",
    )
    if h > extent:
        raise InputError(
            f"edge length {h:g} cm is longer than the largest piece ({extent:.3g} cm across; a shorter "
            "--edge-length meshes it)",
            pattern.source or "--edge-length",
        )
    counts = _segments_for(pattern, h)
    area_cap = AREA_CAP * math.sqrt(3.0) / 4.0 * h * h
    verts, faces, vpiece, pv, pf = [], [], [], [], []
    edge_vertices: dict[EdgeRef, np.ndarray] = {}
    base_v = base_f = 0
    for k, p in enumerate(pattern.pieces):
        parts, starts = [], []
        for e in range(p.n_edges):
            starts.append(sum(len(q) for q in parts))
            parts.append(p.resample_edge(e, counts[EdgeRef(p.name, e)])[:-1])
        boundary = np.concatenate(parts)
        nb = len(boundary)
        inner = _lattice(boundary, h)
        seg = np.c_[np.arange(nb), (np.arange(nb) + 1) % nb]
        res = triangle.triangulate(
            {"vertices": np.vstack([boundary, inner]), "segments": seg}, f"pq{min_angle:g}a{area_cap:.9g}YQ"
        )
        v, f = res["vertices"], res["triangles"].astype(np.int64)
        if len(v) < nb or not np.array_equal(v[:nb], boundary):
            raise InputError(f"piece {p.name!r}: Triangle changed the boundary (is the outline valid?)")
        t = v[f]
        signed = (t[:, 1, 0] - t[:, 0, 0]) * (t[:, 2, 1] - t[:, 0, 1]) - (t[:, 1, 1] - t[:, 0, 1]) * (
            t[:, 2, 0] - t[:, 0, 0]
        )
        f = np.where((signed < 0)[:, None], f[:, ::-1], f)
        if p.flipped:
            f = f[:, ::-1]
        for e in range(p.n_edges):
            n = counts[EdgeRef(p.name, e)]
            local = (starts[e] + np.arange(n + 1)) % nb
            edge_vertices[EdgeRef(p.name, e)] = base_v + local
        verts.append(v)
        faces.append(f + base_v)
        vpiece.append(np.full(len(v), k, dtype=np.int32))
        pv.append((base_v, base_v + len(v)))
        pf.append((base_f, base_f + len(f)))
        base_v += len(v)
        base_f += len(f)
    vertices_cm = np.concatenate(verts)
    seam_vertices = []
    for s in pattern.seams:
        a = edge_vertices[s.a]
        b = edge_vertices[s.b]
        seam_vertices.append(np.stack([a, b[::-1] if s.reversed else b], axis=-1))
    # 3D positions: placement hints, or flat beside the body.
    positions = np.zeros((len(vertices_cm), 3))
    placed = np.array([p.placement is not None for p in pattern.pieces])
    x = 1.0
    for k, p in enumerate(pattern.pieces):
        s0, s1 = pv[k]
        if p.placement is not None:
            positions[s0:s1] = p.placement.apply(vertices_cm[s0:s1])
        else:
            v = vertices_cm[s0:s1] / 100.0
            lo, hi = v.min(axis=0), v.max(axis=0)
            positions[s0:s1, :2] = v - lo + [x, 0.0]
            x += float(hi[0] - lo[0]) + 0.1
    return PatternMesh(
        pattern.name,
        pattern.piece_names,
        vertices_cm,
        positions,
        np.concatenate(faces),
        np.concatenate(vpiece),
        np.array(pv, dtype=np.int64).reshape(-1, 2),
        np.array(pf, dtype=np.int64).reshape(-1, 2),
        edge_vertices,
        seam_vertices,
        placed,
        h,
        pattern_layers(pattern.meta, pattern.piece_names),
    )


def obj_text(mesh: PatternMesh, *, placed: bool = True, seams: list | None = None) -> str:
    """Wavefront OBJ of a pattern mesh (SPEC §3.3 conventions).

    `v`: positions in metres (placed, or flat); `vt`: the pattern position in metres, piece-local, un-normalised;
    `f v/vt` (one vt per vertex); a group `g <piece>` per piece; comments `# kitsuke piece <name> <first_face>
    <last_face>` (faces numbered from 0 in file order, last included) and, per seam, `# kitsuke seam <index>
    <piece>:<edge> <piece>:<edge>` (when the pattern's `seams` are given) followed by
    `# kitsuke seam-pairs <index> i/j ...` (1-based OBJ vertex numbers sewn together). Seam vertices are not
    shared: this is the unsewn pattern.
    """
    pos = mesh.positions_m if placed else mesh.flat_positions_m()
    uv = mesh.uv()
    lines = [
        f"# kitsuke pattern mesh {mesh.name}: {len(mesh.piece_names)} pieces, {mesh.n_vertices} vertices, "
        f"{mesh.n_faces} faces, target edge {mesh.edge_length_cm:g} cm",
        "# v: metres (placed); vt: pattern position in metres, piece-local",
    ]
    for k, name in enumerate(mesh.piece_names):
        f0, f1 = mesh.piece_faces[k]
        lines.append(f"# kitsuke piece {name} {f0} {f1 - 1}")
    for i, pairs in enumerate(mesh.seam_vertices):
        if seams is not None:
            lines.append(f"# kitsuke seam {i} {seams[i].a} {seams[i].b}")
        lines.append(f"# kitsuke seam-pairs {i} " + " ".join(f"{a + 1}/{b + 1}" for a, b in pairs))
    lines += [f"v {x:.6f} {y:.6f} {z:.6f}" for x, y, z in pos]
    lines += [f"vt {u:.6f} {v:.6f}" for u, v in uv]
    for k, name in enumerate(mesh.piece_names):
        lines.append(f"g {name}")
        f0, f1 = mesh.piece_faces[k]
        lines += [f"f {a}/{a} {b}/{b} {c}/{c}" for a, b, c in mesh.faces[f0:f1] + 1]
    return "\n".join(lines) + "\n"


def write_pattern_obj(
    mesh: PatternMesh, path: str | os.PathLike[str], *, placed: bool = True, seams: list | None = None
) -> None:
    """Write `obj_text(mesh, ...)` atomically."""
    write_text_atomic(path, obj_text(mesh, placed=placed, seams=seams))


#: `mesh_quality`'s "min_angle_away_deg" leaves out triangles within this many target edge lengths of an outline
#: corner sharper than the mesher's minimum angle (no mesh of such a corner has better angles next to it).
SHARP_CORNER_REACH = 2.0


def _corner_angles(mesh: PatternMesh) -> tuple[np.ndarray, np.ndarray]:
    """The pieces' outline corners: vertex indices (C,) and interior angles (C,) degrees."""
    v = mesh.vertices_cm
    corners, angles = [], []
    for name in mesh.piece_names:
        chain = [mesh.edge_vertices[r] for r in sorted(mesh.edge_vertices, key=lambda r: r.edge) if r.piece == name]
        if not chain:
            continue
        ring = np.concatenate([c[:-1] for c in chain])  # the outline, each vertex once, in outline order
        x, y = v[ring, 0], v[ring, 1]
        turn = 1.0 if (x * np.roll(y, -1) - np.roll(x, -1) * y).sum() > 0 else -1.0  # counter-clockwise: +1
        for i, c in enumerate(chain):
            here, nxt, prev = int(c[0]), int(c[1]), int(chain[i - 1][-2])  # the previous edge's last segment
            a, b = v[nxt] - v[here], v[prev] - v[here]
            ang = np.degrees(np.arctan2(turn * (a[0] * b[1] - a[1] * b[0]), a @ b)) % 360.0
            corners.append(here)
            angles.append(ang)
    return np.array(corners, dtype=np.int64), np.array(angles)


def mesh_quality(mesh: PatternMesh, *, min_angle: float = 25.0) -> dict:
    """Quality figures of a pattern mesh: minimum angle (degrees), the same away from outline corners sharper than
    `min_angle` (the mesher's minimum: a corner of 16 degrees, the kimono okumi's point, has a triangle that sharp
    in it and one or two nearly as sharp next to it) and the sharpest corner, interior edge lengths relative to the
    target (fraction within 30 %, 1st/50th/99th percentiles), longest boundary segment relative to the target."""
    v, f = mesh.vertices_cm, mesh.faces
    t = v[f]
    angles = []
    for i in range(3):
        a, b, c = t[:, i], t[:, (i + 1) % 3], t[:, (i + 2) % 3]
        u, w = b - a, c - a
        angles.append(np.degrees(np.arctan2(np.abs(u[:, 0] * w[:, 1] - u[:, 1] * w[:, 0]), (u * w).sum(1))))
    smallest = np.min(angles, axis=0)
    corner, corner_deg = _corner_angles(mesh)
    sharp = corner[corner_deg < min_angle]
    away = np.ones(len(f), dtype=bool)
    centre, piece = t.mean(axis=1), mesh.vertex_piece[f[:, 0]]
    for c in sharp:
        away &= (np.linalg.norm(centre - v[c], axis=1) > SHARP_CORNER_REACH * mesh.edge_length_cm) | (
            piece != mesh.vertex_piece[c]
        )
    edges = np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1)
    edges, count = np.unique(edges, axis=0, return_counts=True)
    rel = np.linalg.norm(v[edges[:, 0]] - v[edges[:, 1]], axis=1) / mesh.edge_length_cm
    inner = rel[count == 2]
    return {
        "min_angle_deg": float(smallest.min()),
        "min_angle_away_deg": float(smallest[away].min()) if away.any() else float(smallest.min()),
        "sharpest_corner_deg": float(corner_deg.min()) if len(corner_deg) else 180.0,
        "interior_edges": int(len(inner)),
        "interior_within_30pct": float(np.mean(np.abs(inner - 1) <= 0.3)) if len(inner) else 1.0,
        "interior_length_p1_p50_p99": [float(x) for x in np.percentile(inner, [1, 50, 99])] if len(inner) else [],
        "boundary_max": float(rel[count == 1].max()),
    }
