"""The sewing-pattern data model: Curve, Fold, Placement, Piece, EdgeRef, Seam, Pattern.

Conventions (SPEC §2, §3.1):

- A piece's outline is a closed polygon in piece-local **centimetres**, counter-clockwise seen from the piece's
  outer (front) face; the outer face is the piece's local +Z side. Edge *i* runs from outline point *i* to point
  *i + 1* (wrapping), optionally curved.
- Curves use GarmentCode's relative control points (see `_geometry`): x along the edge 0..1, y across it as a
  fraction of the edge length, positive to the left of the edge's direction (into a counter-clockwise piece).
- A seam joins two whole edges; `reversed=True` means edge a's start meets edge b's end (the usual case for two
  pieces that both face outwards).
- A placement is an optional hint for where a piece hangs around a standing body (metres, Y up, facing +Z):
  world = R @ (local / 100) + translation, with R from XYZ Euler degrees (R = Rz Ry Rx, GarmentCode's order), and
  an optional fold for pieces that run over a shoulder (`Fold`).

The types coerce and shape-check their arrays on construction and raise `InputError` for malformed data; deeper
checks (self-intersection, seams naming unknown edges, length mismatches) live in `validate`.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np

from .. import limits
from ..errors import InputError
from . import _geometry as geo

CurveType = Literal["quadratic", "cubic", "circle"]


def _finite_array(value: Any, shape_tail: tuple[int, ...], what: str) -> np.ndarray:
    try:
        arr = np.array(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise InputError(f"{what} must be numbers") from None
    if arr.ndim != 1 + len(shape_tail) or arr.shape[1:] != shape_tail:
        want = "(n, " + ", ".join(map(str, shape_tail)) + ")" if shape_tail else "(n,)"
        raise InputError(f"{what} must have shape {want}, got {arr.shape}")
    if not np.isfinite(arr).all():
        raise InputError(f"{what} holds NaN or infinity")
    return arr


@dataclass(frozen=True)
class Curve:
    """The curvature of one edge.

    Attributes
    ----------
    type : "quadratic" (one control point), "cubic" (two) — Bézier curves — or "circle" (one point (0.5, y): the
        circular arc through the edge's ends and that point; GarmentCode's circle edges).
    control : (k, 2) float64, relative control points (x along the edge 0..1, y across it as a fraction of the edge
        length, positive to the left of the edge's direction).
    """

    type: CurveType
    control: np.ndarray

    def __post_init__(self) -> None:
        if not isinstance(self.type, str) or self.type not in geo.CONTROL_COUNT:
            raise InputError(f"unknown curve type {self.type!r} (use quadratic, cubic or circle)")
        k = geo.CONTROL_COUNT[self.type]
        ctrl = _finite_array(self.control, (2,), "curve control")
        if len(ctrl) != k:
            raise InputError(f"a {self.type} curve needs {k} control point{'s' * (k > 1)}, got {len(ctrl)}")
        if self.type == "circle" and abs(ctrl[0, 0] - 0.5) > 1e-6:
            raise InputError("a circle curve's control point must have x = 0.5 (the middle of the arc)")
        ctrl.setflags(write=False)
        object.__setattr__(self, "control", ctrl)

    def reversed(self) -> Curve:
        """The same curve for the edge traversed the other way (x -> 1 - x, y -> -y, order reversed)."""
        return Curve(self.type, np.stack([1.0 - self.control[::-1, 0], -self.control[::-1, 1]], axis=-1))

    def mirrored(self) -> Curve:
        """The curve of the edge after mirroring the piece (the edge keeps its direction): y -> -y."""
        return Curve(self.type, self.control * np.array([1.0, -1.0]))

    def __eq__(self, other: object) -> bool:
        return (
            isinstance(other, Curve)
            and self.type == other.type
            and self.control.shape == other.control.shape
            and bool(np.allclose(self.control, other.control, rtol=0, atol=1e-12))
        )

    __hash__ = None  # type: ignore[assignment]


@dataclass(frozen=True)
class Fold:
    """A fold across a piece for its placement hint: a strip that runs over a shoulder (kimono body panels, sleeves).

    The part of the piece above the line y = `y_cm` (piece coordinates) is bent backwards — towards the piece's
    local -Z, behind its outer face — around a half cylinder of diameter `diameter_cm` whose axis is parallel to
    the piece's x axis, centred on the fold line. The bend is isometric (no stretch), so a placed mesh starts at
    rest. Only the placement uses it; the flat pattern is unchanged.
    """

    y_cm: float
    diameter_cm: float

    def __post_init__(self) -> None:
        if not (math.isfinite(self.y_cm) and math.isfinite(self.diameter_cm)) or self.diameter_cm <= 0:
            raise InputError("fold needs a finite y_cm and a positive diameter_cm")

    def bend(self, points_cm: np.ndarray) -> np.ndarray:
        """Piece points (n, 2) cm -> local 3D points (n, 3) cm with the fold applied (z = 0 below it)."""
        p = np.asarray(points_cm, dtype=np.float64).reshape(-1, 2)
        r = 0.5 * self.diameter_cm
        y0 = self.y_cm - 0.5 * math.pi * r  # where the bend starts; it ends at y0 + pi r
        s = p[:, 1] - y0
        phi = np.clip(s / r, 0.0, math.pi)
        y = np.where(s <= 0, p[:, 1], y0 + r * np.sin(phi))
        z = np.where(s <= 0, 0.0, -r * (1.0 - np.cos(phi)))
        beyond = s > math.pi * r
        y = np.where(beyond, y0 - (s - math.pi * r), y)
        z = np.where(beyond, -2.0 * r, z)
        return np.stack([p[:, 0], y, z], axis=-1)


@dataclass
class Placement:
    """Where a piece hangs around a standing body (a hint for wrapping and previews).

    Attributes
    ----------
    translation : (3,) float64, metres, world frame (Y up, the body faces +Z): where the piece origin goes.
    rotation_deg : (3,) float64, XYZ Euler angles in degrees, R = Rz @ Ry @ Rx (GarmentCode's order).
    fold : optional `Fold` applied in piece coordinates before the rotation.
    """

    translation: np.ndarray = field(default_factory=lambda: np.zeros(3))
    rotation_deg: np.ndarray = field(default_factory=lambda: np.zeros(3))
    fold: Fold | None = None

    def __post_init__(self) -> None:
        self.translation = _finite_array([self.translation], (3,), "placement translation")[0]
        self.rotation_deg = _finite_array([self.rotation_deg], (3,), "placement rotation_deg")[0]

    @property
    def matrix(self) -> np.ndarray:
        """(3, 3) float64 rotation matrix (local piece axes -> world)."""
        return geo.euler_xyz_matrix(self.rotation_deg)

    @property
    def normal(self) -> np.ndarray:
        """(3,) unit vector: the direction the piece's outer face looks to (local +Z in the world), below any fold."""
        return self.matrix[:, 2].copy()

    def apply(self, points_cm: np.ndarray) -> np.ndarray:
        """Piece points (n, 2) cm -> world points (n, 3) metres."""
        p = np.asarray(points_cm, dtype=np.float64).reshape(-1, 2)
        local = self.fold.bend(p) if self.fold is not None else np.c_[p, np.zeros(len(p))]
        return (local / 100.0) @ self.matrix.T + self.translation

    def __eq__(self, other: object) -> bool:
        return (
            isinstance(other, Placement)
            and bool(np.allclose(self.translation, other.translation, rtol=0, atol=1e-12))
            and bool(np.allclose(self.rotation_deg, other.rotation_deg, rtol=0, atol=1e-9))
            and self.fold == other.fold
        )

    __hash__ = None  # type: ignore[assignment]


@dataclass
class Piece:
    """One pattern piece.

    Attributes
    ----------
    name : unique within its pattern.
    outline : (n, 2) float64, centimetres, piece-local; counter-clockwise seen from the outer face (n >= 3).
    curves : {edge index: Curve} for the curved edges; the others are straight.
    flipped : the piece is turned over: its back face is the outside (meshes reverse their winding).
    placement : optional placement hint around the body.
    """

    name: str
    outline: np.ndarray
    curves: dict[int, Curve] = field(default_factory=dict)
    flipped: bool = False
    placement: Placement | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name.strip():
            raise InputError("a piece needs a non-empty name")
        self.outline = np.ascontiguousarray(_finite_array(self.outline, (2,), f"piece {self.name!r}: outline"))
        n = len(self.outline)
        if n < 3:
            raise InputError(f"piece {self.name!r}: outline has {n} points, a piece needs at least 3")
        curves: dict[int, Curve] = {}
        for k, c in dict(self.curves).items():
            i = int(k)
            if not 0 <= i < n:
                raise InputError(f"piece {self.name!r}: curve on edge {i}, but the outline has edges 0..{n - 1}")
            if not isinstance(c, Curve):
                raise InputError(f"piece {self.name!r}: edge {i}: curve must be a Curve")
            curves[i] = c
        self.curves = dict(sorted(curves.items()))
        self.flipped = bool(self.flipped)
        self._check_size()

    def _check_size(self) -> None:
        """Refuse a piece past the size limits before anything samples or meshes it (a 10^9 cm arc would be
        sampled into billions of points)."""
        name = f"piece {self.name!r}"
        for i in range(self.n_edges):
            length = geo.curve_length_bound(*self._curve_args(i))
            if not math.isfinite(length):
                raise InputError(f"{name}: edge {i} has no finite length")
            limits.check("edge_m", length / 100.0, f"{name}: edge {i} is {length / 100.0:,.4g} m long")
        area = self.area
        if not math.isfinite(area):
            raise InputError(f"{name}: outline has no finite area")
        limits.check("piece_m2", area / 1e4, f"{name}: its area is {area / 1e4:,.4g} m²")

    # -- edges -----------------------------------------------------------------------------------------------
    @property
    def n_edges(self) -> int:
        return len(self.outline)

    def edge_endpoints(self, edge: int) -> tuple[np.ndarray, np.ndarray]:
        """Start and end point (2,) cm of edge `edge`."""
        n = self.n_edges
        return self.outline[edge % n], self.outline[(edge + 1) % n]

    def _curve_args(self, edge: int) -> tuple[np.ndarray, np.ndarray, str | None, np.ndarray | None]:
        p0, p1 = self.edge_endpoints(edge)
        c = self.curves.get(edge % self.n_edges)
        return p0, p1, (c.type if c else None), (c.control if c else None)

    def sample_edge(self, edge: int, *, tol_cm: float = geo.SAMPLE_TOL_CM) -> np.ndarray:
        """Polyline (m, 2) cm of the edge, both ends included, within `tol_cm` of the true curve (m = 2 if straight)."""
        return geo.sample_curve(*self._curve_args(edge), tol_cm)

    def edge_points(self, edge: int, t: np.ndarray) -> np.ndarray:
        """Points (len(t), 2) cm on the edge at curve parameters t in [0, 1]."""
        return geo.curve_points(*self._curve_args(edge), np.asarray(t, dtype=np.float64))

    def resample_edge(self, edge: int, n_segments: int) -> np.ndarray:
        """(n_segments + 1, 2) cm points equally spaced by arc length along the edge, ends exact."""
        if n_segments < 1:
            raise ValueError("n_segments must be at least 1")
        return geo.resample_polyline(self.sample_edge(edge, tol_cm=geo.MEASURE_TOL_CM), n_segments)

    def edge_length(self, edge: int) -> float:
        """Arc length of the edge, cm (exact for lines and arcs; Béziers measured along a polyline within 1e-3 cm)."""
        return geo.curve_length(*self._curve_args(edge), geo.MEASURE_TOL_CM)

    def edge_lengths(self) -> np.ndarray:
        """(n_edges,) float64 arc lengths, cm."""
        return np.array([self.edge_length(i) for i in range(self.n_edges)])

    # -- the whole outline ------------------------------------------------------------------------------------
    def polygon(self, *, tol_cm: float = geo.SAMPLE_TOL_CM) -> np.ndarray:
        """The densified outline (m, 2) cm, curves sampled within `tol_cm`, first point not repeated."""
        return self.polygon_with_edges(tol_cm=tol_cm)[0]

    def polygon_with_edges(self, *, tol_cm: float = geo.SAMPLE_TOL_CM) -> tuple[np.ndarray, np.ndarray]:
        """The densified outline (m, 2) cm and, per point, the edge (m,) int64 that starts at or runs through it."""
        parts = [self.sample_edge(i, tol_cm=tol_cm)[:-1] for i in range(self.n_edges)]
        edge_of = np.concatenate([np.full(len(p), i, dtype=np.int64) for i, p in enumerate(parts)])
        return np.concatenate(parts), edge_of

    @property
    def signed_area(self) -> float:
        """Area in cm^2 (exact for curved edges too), positive when the outline runs counter-clockwise."""
        return float(sum(geo.edge_area_term(*self._curve_args(i)) for i in range(self.n_edges)))

    @property
    def area(self) -> float:
        """Area in cm^2 (curves included)."""
        return abs(self.signed_area)

    @property
    def perimeter(self) -> float:
        return float(self.edge_lengths().sum())

    @property
    def bounds(self) -> np.ndarray:
        """(2, 2) float64: min and max corner of the densified outline, cm."""
        poly = self.polygon()
        return np.stack([poly.min(axis=0), poly.max(axis=0)])

    def copy(self) -> Piece:
        pl = self.placement
        return Piece(
            self.name,
            self.outline.copy(),
            dict(self.curves),
            self.flipped,
            None if pl is None else Placement(pl.translation.copy(), pl.rotation_deg.copy(), pl.fold),
        )

    def __eq__(self, other: object) -> bool:
        return (
            isinstance(other, Piece)
            and self.name == other.name
            and self.outline.shape == other.outline.shape
            and bool(np.allclose(self.outline, other.outline, rtol=0, atol=1e-9))
            and self.curves == other.curves
            and self.flipped == other.flipped
            and self.placement == other.placement
        )

    __hash__ = None  # type: ignore[assignment]


@dataclass(frozen=True)
class EdgeRef:
    """One edge of one piece: (piece name, edge index)."""

    piece: str
    edge: int

    def __str__(self) -> str:
        return f"{self.piece}:{self.edge}"


@dataclass(frozen=True)
class Seam:
    """Two edges sewn together. `reversed=True`: a's start meets b's end (the usual case for two pieces that both
    face outwards, because their counter-clockwise outlines run opposite ways along a shared line)."""

    a: EdgeRef
    b: EdgeRef
    reversed: bool = True


@dataclass
class Pattern:
    """A sewing pattern: pieces and the seams between them.

    Attributes
    ----------
    name : a label (file exports, reports).
    pieces : list of Piece, names unique.
    seams : list of Seam.
    meta : free-form JSON-serialisable information (where it came from, generator parameters, edge names);
        kept through kitsuke JSON files.
    file_mirrored : names of the pieces whose coordinates in the file the pattern was read from are mirrored
        (x -> -x) against the piece's own: a GarmentCode back panel, which runs clockwise there. Strokes are
        drawn in the file's coordinates (`file_to_piece`); a kitsuke JSON file written from this pattern holds
        the piece's own coordinates, so this is not saved.
    source : the file it was read from, or None; errors about the pattern as a whole name it.
    """

    name: str
    pieces: list[Piece] = field(default_factory=list)
    seams: list[Seam] = field(default_factory=list)
    meta: dict[str, Any] = field(default_factory=dict)
    file_mirrored: frozenset[str] = field(default_factory=frozenset, compare=False)
    source: str | None = field(default=None, compare=False)

    def without(self, names: Iterable[str]) -> Pattern:
        """This pattern without the pieces `names` and every seam sewn to them (a new Pattern; pieces shared)."""
        drop = set(names)
        return dataclasses.replace(
            self,
            pieces=[p for p in self.pieces if p.name not in drop],
            seams=[s for s in self.seams if s.a.piece not in drop and s.b.piece not in drop],
            file_mirrored=self.file_mirrored - drop,
        )

    def file_to_piece(self, piece: str, points: np.ndarray) -> np.ndarray:
        """Points (n, 2) cm in the coordinates of the file the pattern came from -> the piece's own (a copy)."""
        pts = np.array(points, dtype=np.float64)
        if piece in self.file_mirrored:
            pts[..., 0] *= -1.0
        return pts

    def piece_to_file(self, piece: str, points: np.ndarray) -> np.ndarray:
        """The inverse of `file_to_piece` (the mirror is its own inverse)."""
        return self.file_to_piece(piece, points)

    @property
    def piece_names(self) -> list[str]:
        return [p.name for p in self.pieces]

    def piece_index(self, name: str) -> int:
        for i, p in enumerate(self.pieces):
            if p.name == name:
                return i
        raise KeyError(name)

    def piece(self, name: str) -> Piece:
        """The piece called `name` (KeyError if none)."""
        return self.pieces[self.piece_index(name)]

    def edge_length(self, ref: EdgeRef) -> float:
        """Arc length (cm) of the referenced edge."""
        return self.piece(ref.piece).edge_length(ref.edge)

    def seam_points(self, seam: Seam, n_segments: int) -> tuple[np.ndarray, np.ndarray]:
        """Both sides of a seam resampled to matching points: (n+1, 2) cm on a, (n+1, 2) cm on b, row k of a sewn
        to row k of b (b's points are reversed when the seam is)."""
        pa = self.piece(seam.a.piece).resample_edge(seam.a.edge, n_segments)
        pb = self.piece(seam.b.piece).resample_edge(seam.b.edge, n_segments)
        return pa, (pb[::-1] if seam.reversed else pb)

    def copy(self) -> Pattern:
        import copy as _copy

        return Pattern(
            self.name,
            [p.copy() for p in self.pieces],
            list(self.seams),
            _copy.deepcopy(self.meta),
            self.file_mirrored,
            self.source,
        )
