"""Tethers: points on the cloth that must stay within a reach of a polyline (a body stroke, for the wrap).

A one-sided constraint: a point nearer than the reach is left alone, one farther is pulled straight back to it.
So the cloth keeps its own rest wherever that rest already meets the request, and only where it does not is the
cloth moved, by the least it takes (`_kernels.project_tethers`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError
from . import _kernels as K


@dataclass(frozen=True)
class Tethers:
    """Cloth points held within `reach_m` of polylines.

    tri : (n, 3) int64 cloth vertices of the triangle holding each point; bary : (n, 3) float64 its barycentric
    coordinates. line_points : (K, 3) float64 metres, the polylines one after another; line_start : (L + 1,)
    int64, polyline l is line_points[line_start[l]:line_start[l + 1]] (one point: that point); line_of : (n,)
    int64, each point's polyline. reach_m : metres.
    `project` keeps a nearest-segment cache here (see `_kernels.project_tethers`): it skips searches and never
    changes a result.
    """

    tri: np.ndarray
    bary: np.ndarray
    line_points: np.ndarray
    line_start: np.ndarray
    line_of: np.ndarray
    reach_m: float
    _seg: np.ndarray = field(init=False, repr=False, compare=False)
    _second: np.ndarray = field(init=False, repr=False, compare=False)
    _snap: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        n = len(self.tri)
        object.__setattr__(self, "_seg", np.full(n, -1, dtype=np.int64))
        object.__setattr__(self, "_second", np.zeros(n))
        object.__setattr__(self, "_snap", np.zeros((n, 3)))

    @classmethod
    def from_polylines(
        cls, groups: list[tuple[np.ndarray, np.ndarray, np.ndarray]], faces: np.ndarray, reach_m: float
    ) -> Tethers:
        """Tethers from (face indices (n,), barycentric (n, 3), polyline (k, 3)) groups, one per polyline, on a
        cloth whose triangles are `faces` (F, 3)."""
        if not reach_m > 0:
            raise InputError(f"tether reach must be > 0 metres, got {reach_m}")
        tri, bary, lines, line_of = [], [], [], []
        for l, (face_ids, b, line) in enumerate(groups):
            line = np.asarray(line, dtype=np.float64).reshape(-1, 3)
            if len(line) < 1:
                raise InputError(f"tether polyline {l} has no points")
            tri.append(np.asarray(faces)[np.asarray(face_ids, dtype=np.int64)])
            bary.append(np.asarray(b, dtype=np.float64).reshape(-1, 3))
            lines.append(line)
            line_of.append(np.full(len(face_ids), l, dtype=np.int64))
        if not groups:
            return cls(
                np.zeros((0, 3), np.int64),
                np.zeros((0, 3)),
                np.zeros((0, 3)),
                np.zeros(1, np.int64),
                np.zeros(0, np.int64),
                float(reach_m),
            )
        return cls(
            tri=np.ascontiguousarray(np.concatenate(tri), dtype=np.int64),
            bary=np.ascontiguousarray(np.concatenate(bary)),
            line_points=np.ascontiguousarray(np.concatenate(lines)),
            line_start=np.concatenate([[0], np.cumsum([len(x) for x in lines])]).astype(np.int64),
            line_of=np.concatenate(line_of),
            reach_m=float(reach_m),
        )

    def __len__(self) -> int:
        return len(self.tri)

    def nearest(self, positions: np.ndarray) -> np.ndarray:
        """(n, 3) metres: the nearest point of each cloth point's polyline to it (positions (V, 3) metres)."""
        p = np.einsum("nk,nkc->nc", self.bary, positions[self.tri])
        out = np.empty_like(p)
        for line in range(len(self.line_start) - 1):
            sel = np.flatnonzero(self.line_of == line)
            pts = self.line_points[self.line_start[line] : self.line_start[line + 1]]
            if len(pts) == 1 or not len(sel):
                out[sel] = pts[0]
                continue
            a, ab = pts[:-1], pts[1:] - pts[:-1]
            t = np.einsum("nsc,sc->ns", p[sel, None] - a[None], ab) / np.maximum(np.einsum("sc,sc->s", ab, ab), 1e-300)
            q = a[None] + np.clip(t, 0.0, 1.0)[..., None] * ab[None]
            best = np.argmin(np.einsum("nsc,nsc->ns", q - p[sel, None], q - p[sel, None]), axis=1)
            out[sel] = q[np.arange(len(sel)), best]
        return out

    def project(self, positions: np.ndarray, movable: np.ndarray) -> float:
        """One sweep (in place on positions (V, 3)): every point beyond its reach pulled back to it, its vertices
        moving only where `movable` (V,) bool is set on all three. Returns the farthest beyond reach met, metres."""
        if not len(self):
            return 0.0
        return float(
            K.project_tethers(
                positions,
                self.tri,
                self.bary,
                movable,
                self.line_points,
                self.line_start,
                self.line_of,
                self.reach_m,
                self._seg,
                self._second,
                self._snap,
            )
        )
