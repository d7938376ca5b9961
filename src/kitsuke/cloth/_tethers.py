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
from ._model import ClothModel


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

    def refined(self, before: ClothModel, after: ClothModel, parent_face: np.ndarray) -> Tethers:
        """The same tethers on `after`, a refinement of `before` (`kitsuke.cloth.refine`: old vertices keep their
        indices; parent_face (F',) int64, the face of `before` each face of `after` came from). Each point keeps
        its place in the rest shape and moves to the new face that holds it there: after a refinement the cloth
        surface runs through the new vertices, and a point still taken between its old corners lies off it
        (measured on the kimono's sleeve crease: 12.0 mm from its stroke, where the tethers held it 8.7 mm)."""
        if not len(self):
            return self
        old = _face_of(before.faces, self.tri)
        point = np.einsum("nk,nkc->nc", self.bary, before.rest_corners[old])  # (n, 2) metres, rest shape
        # Candidates: the faces that came from the old face or from one across its edges (an edge flip makes a
        # face lying partly in the face across the edge) in the same rest frame: never across a seam, where no
        # edge flips and the rest shapes of the two sides are two pieces' frames.
        order = np.argsort(parent_face, kind="stable")
        start = np.searchsorted(parent_face[order], np.arange(before.n_faces + 1))
        around = np.concatenate([old[:, None], before.face_adjacency[old]], axis=1)  # (n, 4), -1 on a border
        for k in range(3):
            g = around[:, 1 + k]
            a, b = before.faces[old, k], before.faces[old, (k + 1) % 3]
            rest_g = before.rest_corners[np.maximum(g, 0)]
            at_a = rest_g[np.arange(len(old)), np.argmax(before.faces[np.maximum(g, 0)] == a[:, None], axis=1)]
            at_b = rest_g[np.arange(len(old)), np.argmax(before.faces[np.maximum(g, 0)] == b[:, None], axis=1)]
            same = np.isclose(at_a, before.rest_corners[old, k]).all(axis=1) & np.isclose(
                at_b, before.rest_corners[old, (k + 1) % 3]
            ).all(axis=1)
            around[~same, 1 + k] = -1
        counts = np.where(around >= 0, start[np.maximum(around, 0) + 1] - start[np.maximum(around, 0)], 0)
        width = int(counts.sum(axis=1).max())
        cand = np.full((len(old), width), -1, dtype=np.int64)
        col = np.zeros(len(old), dtype=np.int64)
        for k in range(4):  # the four old faces, each a run of children
            for j in range(int(counts[:, k].max(initial=0))):
                has = counts[:, k] > j
                rows = np.flatnonzero(has)
                cand[rows, col[rows]] = order[start[around[rows, k]] + j]
                col[rows] += 1
        c = after.rest_corners[np.maximum(cand, 0)]  # (n, m, 3, 2)
        e1, e2 = c[..., 1, :] - c[..., 0, :], c[..., 2, :] - c[..., 0, :]
        det = e1[..., 0] * e2[..., 1] - e1[..., 1] * e2[..., 0]
        d = point[:, None, :] - c[..., 0, :]
        with np.errstate(divide="ignore", invalid="ignore"):
            u = (d[..., 0] * e2[..., 1] - d[..., 1] * e2[..., 0]) / det
            v = (e1[..., 0] * d[..., 1] - e1[..., 1] * d[..., 0]) / det
        b = np.stack([1.0 - u - v, u, v], axis=-1)
        inside = np.where((cand >= 0) & np.isfinite(b).all(axis=-1), b.min(axis=-1), -np.inf)
        best = np.argmax(inside, axis=1)  # the face the point is most inside
        rows = np.arange(len(old))
        face = cand[rows, best]
        bary = np.clip(b[rows, best], 0.0, 1.0)
        bary /= bary.sum(axis=1, keepdims=True)
        return Tethers(
            np.ascontiguousarray(after.faces[face]),
            np.ascontiguousarray(bary),
            self.line_points,
            self.line_start,
            self.line_of,
            self.reach_m,
        )

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

    def project(self, positions: np.ndarray, movable: np.ndarray, stamps: tuple | None = None) -> float:
        """One sweep (in place on positions (V, 3)): every point beyond its reach pulled back to it, its vertices
        moving only where `movable` (V,) bool is set on all three. Returns the farthest beyond reach met, metres.
        stamps : (moved (V,), seen (n,), clock (1,)) int64, to skip the points whose vertices have not moved since
        they were last met (`_kernels.project_band`), or None."""
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
                stamps,
            )
        )


def _face_of(faces: np.ndarray, tri: np.ndarray) -> np.ndarray:
    """(n,) the index in faces (F, 3) of each triangle of tri (n, 3) (same vertices, any order)."""
    key_f = np.sort(faces, axis=1)
    key_t = np.sort(tri, axis=1)
    n = int(max(faces.max(initial=0), tri.max(initial=0))) + 1
    kf = (key_f[:, 0] * n + key_f[:, 1]) * n + key_f[:, 2]
    kt = (key_t[:, 0] * n + key_t[:, 1]) * n + key_t[:, 2]
    order = np.argsort(kf)
    at = np.clip(np.searchsorted(kf[order], kt), 0, len(kf) - 1)
    if (kf[order][at] != kt).any():
        raise InputError("tethers name a triangle the cloth does not have")
    return order[at]
