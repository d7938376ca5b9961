"""Helpers shared by the tools that make the packaged stroke files (tools/make_*_strokes.py).

The strokes ask the garment to sit where a garment of its kind naturally hangs: from the shoulders. Everything
here works on plane sections of the body (trimesh), so it needs no rig:

- `Slicer.loop(point, normal)`: the closed section of the body through a point, in the plane with that normal.
- `Slicer.down_from_ridge(x, toward, ...)`: the surface path in the plane x = const from the shoulder ridge (the
  section's highest point) down the front (toward = +1, +z) or the back (-1), as drawn surface points.
- `Slicer.top_line(xs)`: the line along the top of the shoulder and the arm (highest point of each x section),
  and `Slicer.around(line, offset_m, toward)`: that line moved around the body by a surface distance, in planes
  across it (a sleeve's stroke a little in front of or behind its top seam).
- `pattern_top(piece, u)`: where a vertical line through a piece leaves it at the top (neckline or shoulder).
- `pair(...)`, `write_strokes_file(...)`: stroke pairs (rounded to 0.1 mm) and a validated strokes file.

Body strokes are drawn points lying on the surface (resolve_strokes projects them onto it again, which moves them
by nothing); pattern strokes are straight lines, each as long as its body stroke (length ratio 1), unless a
script says otherwise.
"""

from __future__ import annotations

import numpy as np
import trimesh

from kitsuke.dressing import arc_length, in_file_frame, interpolate_polyline, strokes_from_dict, write_strokes
from kitsuke.geometry import TriMesh
from kitsuke.pattern import Pattern, Piece

#: Spacing of the points of a drawn body stroke along its path, metres (the wrap follows the surface between them).
BODY_STEP_M = 0.02


def _closed(loop: np.ndarray) -> np.ndarray:
    """A closed polyline (m, 3) without its repeated last point."""
    return loop[:-1] if len(loop) > 2 and np.allclose(loop[0], loop[-1]) else loop


class Slicer:
    """Plane sections of a body mesh (metres, Y up, facing +Z)."""

    def __init__(self, mesh: TriMesh):
        self.tm = trimesh.Trimesh(mesh.vertices, mesh.faces, process=False)

    def loop(self, point: np.ndarray, normal: np.ndarray) -> np.ndarray:
        """(m, 3) the closed section loop, in the plane through `point` with `normal`, that passes nearest to
        `point`."""
        s = self.tm.section(plane_origin=np.asarray(point, float), plane_normal=np.asarray(normal, float))
        if s is None:
            raise ValueError(f"no section of the body through {point}")
        loops = [_closed(np.asarray(p)) for p in s.discrete]
        d = [np.linalg.norm(p - point, axis=1).min() for p in loops]
        return loops[int(np.argmin(d))]

    def ridge(self, x: float, near_y: float) -> np.ndarray:
        """(3,) the highest point of the body's section at x (the loop passing nearest to (x, near_y, 0))."""
        lp = self.loop(np.array([x, near_y, 0.0]), np.array([1.0, 0.0, 0.0]))
        return lp[np.argmax(lp[:, 1])]

    @staticmethod
    def walk(loop: np.ndarray, start: np.ndarray, toward: float, arcs: np.ndarray) -> np.ndarray:
        """(k, 3) points at arc lengths `arcs` (metres, >= 0) along a closed loop from its point nearest `start`,
        going the way in which z grows (toward = +1) or falls (-1)."""
        i = int(np.argmin(np.linalg.norm(loop - start, axis=1)))
        fwd = np.roll(loop, -i, axis=0)
        ring = np.vstack([fwd, fwd[:1]])
        # Which way round the loop goes toward +z (judged a few cm along, past any flat top).
        k = min(len(fwd) // 8, 10)
        if (fwd[k, 2] - fwd[-k, 2]) * toward < 0:
            ring = ring[::-1]
        return interpolate_polyline(ring, np.asarray(arcs, float))

    def down_from_ridge(
        self,
        x: float,
        toward: float,
        *,
        near_y: float,
        start_m: float,
        stop: str | float = "prominent",
        min_y: float = -np.inf,
        short_m: float = 0.0,
    ) -> tuple[np.ndarray, np.ndarray]:
        """The surface path in the plane x from the ridge down the front (toward = +1) or back (-1).

        Returns (points (k, 3), arc (k,)): drawn points every BODY_STEP_M from `start_m` below the ridge (arc
        length over the surface) to `stop` — "prominent": the most forward (front) / backward (back) point of the
        path, where hanging cloth leaves the body; or a number: that arc length from the ridge, metres — and not
        below height `min_y`; then `short_m` shorter. `arc` is each point's arc length from the ridge.
        """
        lp = self.loop(np.array([x, near_y, 0.0]), np.array([1.0, 0.0, 0.0]))
        top = lp[np.argmax(lp[:, 1])]
        fine = np.arange(0.0, 0.6, 0.002)
        path = self.walk(lp, top, toward, fine)
        ok = np.flatnonzero(path[:, 1] >= min_y)
        last = int(ok[np.argmax(np.diff(np.r_[ok, -1]) != 1)]) if len(ok) else 0  # first run only
        if stop == "prominent":
            end = int(np.argmax(path[: last + 1, 2] * toward))
        else:
            end = min(int(np.searchsorted(fine, float(stop))), last)
        s_end = fine[end] - short_m
        if s_end <= start_m + BODY_STEP_M:
            raise ValueError(f"body path at x={x} too short ({s_end:.3f} m)")
        n = max(2, int(round((s_end - start_m) / BODY_STEP_M)) + 1)
        arcs = np.linspace(start_m, s_end, n)
        return interpolate_polyline(path, arcs), arcs

    def top_line(self, xs: np.ndarray, near_y: float) -> np.ndarray:
        """(k, 3) the highest point of each x section (along the top of the shoulder and the arm), following the
        loop from station to station (each loop chosen nearest to the previous top point)."""
        out = [self.ridge(float(xs[0]), near_y)]
        for x in xs[1:]:
            lp = self.loop(np.array([x, out[-1][1], out[-1][2]]), np.array([1.0, 0.0, 0.0]))
            out.append(lp[np.argmax(lp[:, 1])])
        return np.array(out)

    def around(self, line: np.ndarray, offset_m: float, toward: float) -> np.ndarray:
        """(k, 3) each point of `line` moved `offset_m` over the surface, in the plane across the line there,
        toward the front (+1) or back (-1), smoothed over 7 points (the section loops are polygons, so the moved
        points zigzag by a millimetre or so, which would lengthen the line). offset 0 returns the line."""
        if offset_m <= 0:
            return line.copy()
        t = np.gradient(line, axis=0)
        t /= np.linalg.norm(t, axis=1, keepdims=True)
        return smooth(np.array([self.walk(self.loop(p, n), p, toward, [offset_m])[0] for p, n in zip(line, t)]), 7)


def smooth(points: np.ndarray, width: int = 5) -> np.ndarray:
    """(k, 3) a moving average of a polyline's points over `width` neighbours, ends kept."""
    if len(points) <= width:
        return points.copy()
    ker = np.ones(width) / width
    pad = width // 2
    out = np.stack([np.convolve(np.pad(points[:, i], pad, mode="edge"), ker, mode="valid") for i in range(3)], axis=1)
    out[0], out[-1] = points[0], points[-1]
    return out


def cut(path: np.ndarray, s0: float, s1: float, step: float = BODY_STEP_M) -> np.ndarray:
    """(k, 3) points of a polyline from arc length s0 to s1 (metres), every ~`step`, both ends included."""
    n = max(2, int(round(abs(s1 - s0) / step)) + 1)
    return interpolate_polyline(path, np.linspace(s0, s1, n))


def pattern_top(piece: Piece, u: float) -> float:
    """Highest v (cm) at which the vertical line x = u meets the piece's outline (curves sampled finely)."""
    poly = piece.polygon(tol_cm=0.005)
    a, b = poly, np.roll(poly, -1, axis=0)
    cross = (a[:, 0] - u) * (b[:, 0] - u) <= 0
    cross &= a[:, 0] != b[:, 0]
    t = (u - a[cross, 0]) / (b[cross, 0] - a[cross, 0])
    ys = a[cross, 1] + t * (b[cross, 1] - a[cross, 1])
    if not len(ys):
        raise ValueError(f"x = {u} misses piece {piece.name}")
    return float(ys.max())


def sewn_point(
    pattern: Pattern, piece: str, point_cm: np.ndarray, *, to: str = "", tol_cm: float = 1e-3
) -> tuple[str, np.ndarray]:
    """The (other piece, point (2,) cm) that an outline corner of `piece` is sewn to: the first seam from that
    corner to another piece whose name contains `to`."""
    point_cm = np.asarray(point_cm, float)
    for seam in pattern.seams:
        for ea, eb in ((seam.a, seam.b), (seam.b, seam.a)):
            if ea.piece != piece or eb.piece == piece or to not in eb.piece:
                continue
            p0, p1 = pattern.piece(ea.piece).edge_endpoints(ea.edge)
            q0, q1 = pattern.piece(eb.piece).edge_endpoints(eb.edge)
            for p, q in ((p0, q1), (p1, q0)) if seam.reversed else ((p0, q0), (p1, q1)):
                if np.linalg.norm(p - point_cm) < tol_cm:
                    return eb.piece, q.copy()
    raise ValueError(f"no seam from {piece} at {point_cm} to another piece")


def edge_crossing(piece: Piece, v: float, near_u: float) -> float:
    """The u (cm) where the horizontal line y = v crosses the piece's outline, the crossing nearest `near_u`."""
    poly = piece.polygon(tol_cm=0.005)
    a, b = poly, np.roll(poly, -1, axis=0)
    c = ((a[:, 1] - v) * (b[:, 1] - v) <= 0) & (a[:, 1] != b[:, 1])
    t = (v - a[c, 1]) / (b[c, 1] - a[c, 1])
    us = a[c, 0] + t * (b[c, 0] - a[c, 0])
    if not len(us):
        raise ValueError(f"y = {v} misses piece {piece.name}")
    return float(us[np.argmin(np.abs(us - near_u))])


def inset_path(piece: Piece, edges: list[int], inset_cm: float, step_cm: float = 0.25) -> np.ndarray:
    """(m, 2) cm: the chain of consecutive outline edges `edges` (in outline order), moved `inset_cm` into the
    piece (along the inward normal, left of the counter-clockwise outline), resampled every `step_cm`."""
    pts = np.vstack([piece.sample_edge(e, tol_cm=0.005)[:-1] for e in edges] + [piece.edge_endpoints(edges[-1])[1]])
    s = arc_length(pts)
    pts = interpolate_polyline(pts, np.arange(0.0, s[-1] + 1e-9, step_cm))
    t = np.gradient(pts, axis=0)
    t /= np.linalg.norm(t, axis=1, keepdims=True)
    inward = np.c_[-t[:, 1], t[:, 0]]
    return pts + inset_cm * inward


def vertical_stroke(u: float, v_top: float, length_cm: float, n: int) -> np.ndarray:
    """(n, 2) cm: a straight pattern stroke at x = u from v_top down by length_cm."""
    return np.c_[np.full(n, u), np.linspace(v_top, v_top - length_cm, n)]


def torso_pair(
    pid: int,
    slicer: Slicer,
    piece: Piece,
    u_cm: float,
    x_m: float,
    toward: float,
    *,
    near_y: float,
    top_gap_cm: float,
    min_y: float,
    short_m: float = 0.0,
) -> dict:
    """A torso panel's stroke: the vertical line x = u_cm on the piece from `top_gap_cm` below its top edge (the
    shoulder seam), and on the body the path in the plane x = x_m from `top_gap_cm` past the shoulder ridge down
    the front (toward = +1) or back (-1) to where the chest (shoulder blade) stands out most, not below `min_y`
    (`Slicer.down_from_ridge`); the pattern stroke as long as the body stroke."""
    pts, _ = slicer.down_from_ridge(x_m, toward, near_y=near_y, start_m=top_gap_cm / 100, min_y=min_y, short_m=short_m)
    length_cm = 100 * float(arc_length(pts)[-1])
    v_top = pattern_top(piece, u_cm) - top_gap_cm
    if v_top - length_cm < 0.5:
        raise ValueError(f"{piece.name}: body stroke ({length_cm:.1f} cm) longer than the piece below its top")
    return pair(pid, piece.name, vertical_stroke(u_cm, v_top, length_cm, len(pts)), pts)


def pair(pid: int, piece: str, pattern_cm: np.ndarray, body_m: np.ndarray) -> dict:
    """One stroke pair as a JSON-ready dict: drawn body points (metres, rounded to 0.1 mm) and pattern points (cm,
    rounded to 0.1 mm)."""
    return {
        "id": pid,
        "pattern": {"piece": piece, "points": np.round(np.asarray(pattern_cm, float), 2).tolist()},
        "body": {"points": np.round(np.asarray(body_m, float), 4).tolist()},
    }


def length_ratio(p: dict) -> float:
    """Body stroke length / pattern stroke length of a pair dict (1 = the stroke asks for no stretch)."""
    return float(
        arc_length(np.array(p["body"]["points"]))[-1] / (arc_length(np.array(p["pattern"]["points"]))[-1] / 100)
    )


def write_strokes_file(pairs: list[dict], meta: dict, out: str, pattern: Pattern | None = None) -> None:
    """Validate the pairs (pattern points in the pieces' own coordinates) as a kitsuke strokes v1 document and
    write it (atomically) in the coordinates of `pattern`'s file (GarmentCode's back panels mirrored back),
    printing a summary."""
    doc = {"format": "kitsuke.strokes", "version": 1, "target": "body", "pairs": pairs, "meta": meta}
    strokes = strokes_from_dict(doc)
    write_strokes(strokes if pattern is None else in_file_frame(strokes, pattern), out)
    for p in pairs:
        pts = np.array(p["pattern"]["points"])
        print(
            f"  stroke {p['id']:2d} {p['pattern']['piece']:14s} pattern {pts[0].round(1)} -> {pts[-1].round(1)}"
            f"  body {np.array(p['body']['points'][0]).round(3)} -> {np.array(p['body']['points'][-1]).round(3)}"
            f"  ratio {length_ratio(p):.3f}"
        )
    print("wrote", out, len(pairs), "pairs")
