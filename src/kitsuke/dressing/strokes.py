"""Corresponding strokes (SPEC §3.2, §4.1): what the user draws to say how a garment goes on.

A `StrokePair` joins a stroke drawn on one pattern piece (2D, cm) to a stroke drawn on the body (3D, metres) —
or, for a re-wrap, on a garment already on the body. Pairs are matched by `id`; their order is the drawing
order. A body stroke is given either as points near the surface (each projected onto its closest surface
point) or in the paper's laser mode, as rays (origin, direction) of which the first or the last surface hit is
taken: the same rays with `"first"` and `"last"` draw a stroke on the front and one on the back at once.

File layout (`kitsuke.strokes` v1)::

    {"format": "kitsuke.strokes", "version": 1, "target": "body",            # or "garment"; default "body"
     "pairs": [{"id": 1,
                "pattern": {"piece": "front", "points": [[12.0, 40.0], [12.0, 90.0]]},         # cm
                "body": {"points": [[0.0, 1.35, 0.12], [0.0, 1.00, 0.14]]}},                  # metres
               {"id": 2,
                "pattern": {"piece": "back", "points": [[12.0, 40.0], [12.0, 90.0]]},
                "body": {"laser": {"rays": [[0, 1.35, 2, 0, 0, -1], [0, 1, 2, 0, 0, -1]], "hit": "last"}}}],
     "meta": {}}                                                               # optional, free-form

Three stages, each raising `InputError` that names the file and the stroke id:

- `read_strokes(path)`: the structure (format, version, numbers, at least 2 points, matched and unique ids).
- `check_strokes(strokes, pattern, pattern_mesh=...)`: the pattern side (the piece exists, the points lie on
  it, and — given the meshed pattern — the stroke crosses triangles of it).
- `resolve_strokes(strokes, pattern, surface)`: the body side, projected and cast onto the surface (no point
  farther than 5 cm from it, no laser ray that misses); returns the strokes with every body stroke's surface
  points, faces and barycentric coordinates filled in.
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
import re
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np

from .. import limits
from .._files import read_json, write_text_atomic
from ..errors import InputError
from ..geometry.mesh import TriMesh
from ..geometry.surface import RayHit, Surface, SurfacePoints
from ..pattern import Pattern, PatternMesh, sliver_pieces
from ._crossing import segments_cross_triangles
from ._polyline import (
    arc_length,
    arc_parameters,
    densify_polyline,
    polygon_distance,
    polygon_inside,
    resample_on_surface,
    resample_polyline,
)

FORMAT = "kitsuke.strokes"
VERSION = 1
Target = Literal["body", "garment"]

#: A body point may lie at most this far from the surface it is projected onto, metres (SPEC §3.2 validation).
MAX_SURFACE_DISTANCE_M = 0.05
#: A pattern point may lie this far outside its piece, cm (hand drawing along an edge lands a little off it).
PIECE_TOLERANCE_CM = 0.1
#: Pattern strokes are checked for leaving their piece at samples this far apart, cm.
PIECE_CHECK_STEP_CM = 0.5
#: Shorter strokes have no direction, so no arc-length correspondence: cm on the pattern, metres on the body.
MIN_PATTERN_LENGTH_CM = 0.1
MIN_SURFACE_LENGTH_M = 0.001


def _points_array(value: Any, dim: int, what: str) -> np.ndarray:
    try:
        arr = np.array(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise InputError(f"{what} must be a list of [{', '.join('xyz'[:dim])}] numbers") from None
    if arr.ndim != 2 or arr.shape[1] != dim:
        raise InputError(f"{what} must have shape (n, {dim}), got {arr.shape}")
    bad = ~np.isfinite(arr).all(axis=1)
    if bad.any():
        raise InputError(f"{what}: point {int(np.argmax(bad))} holds NaN or infinity")
    if len(arr) < 2:
        raise InputError(f"{what}: a stroke needs at least 2 points, got {len(arr)}")
    limits.check("points", len(arr), f"{what} has {len(arr):,} points")
    return np.ascontiguousarray(arr)


@dataclass(eq=False)
class PatternStroke:
    """A stroke drawn on one pattern piece.

    Attributes
    ----------
    piece : the piece's name.
    points : (n, 2) float64, centimetres, piece-local pattern coordinates, n >= 2, in drawing order.
    """

    piece: str
    points: np.ndarray

    def __post_init__(self) -> None:
        if not isinstance(self.piece, str) or not self.piece.strip():
            raise InputError("pattern stroke: piece must be a non-empty piece name")
        self.points = _points_array(self.points, 2, "pattern stroke points")
        if self.length_cm < MIN_PATTERN_LENGTH_CM:
            raise InputError(f"pattern stroke has zero length (under {MIN_PATTERN_LENGTH_CM:g} cm)")

    @property
    def length_cm(self) -> float:
        """Arc length, cm."""
        return float(arc_length(self.points)[-1])

    def arc_parameters(self) -> np.ndarray:
        """(n,) float64 in [0, 1]: each point's arc length over the stroke's length."""
        return arc_parameters(self.points)

    def resample(self, k: int) -> np.ndarray:
        """(k, 2) float64 cm: k points equally spaced by arc length, ends kept."""
        return resample_polyline(self.points, k)


@dataclass(eq=False)
class BodyStroke:
    """A stroke on the body (or on a garment, for a re-wrap): drawn points or laser rays, and where they land.

    Attributes
    ----------
    points : (n, 3) float64, metres, world frame: the drawn points (each goes to its closest surface point),
        or None for a laser stroke.
    rays : (n, 6) float64, metres: laser rays, origin xyz then direction xyz (any non-zero length), or None.
    hit : for rays: "first" takes each ray's nearest surface hit (the side facing the origin), "last" the
        farthest (the far side).
    surface : the stroke on the surface once resolved (`resolve_strokes`): points (n, 3) metres, faces (n,),
        barycentric (n, 3), distance (n,) (from the drawn point, or along the ray); None before.
    """

    points: np.ndarray | None = None
    rays: np.ndarray | None = None
    hit: RayHit = "first"
    surface: SurfacePoints | None = field(default=None, repr=False)

    def __post_init__(self) -> None:
        if (self.points is None) == (self.rays is None):
            raise InputError("body stroke: give either points or laser rays (exactly one)")
        if self.points is not None:
            self.points = _points_array(self.points, 3, "body stroke points")
        else:
            self.rays = _points_array(self.rays, 6, "laser rays")
            zero = np.linalg.norm(self.rays[:, 3:], axis=1) <= 0
            if zero.any():
                raise InputError(f"laser ray {int(np.argmax(zero))} has a zero direction")
            if self.hit not in ("first", "last"):
                raise InputError(f"laser hit must be 'first' or 'last', got {self.hit!r}")
        if self.surface is not None and len(self.surface) != self.n_points:
            raise InputError(f"body stroke: {len(self.surface)} surface points for {self.n_points} points")

    @property
    def is_laser(self) -> bool:
        return self.rays is not None

    @property
    def n_points(self) -> int:
        return len(self.rays if self.points is None else self.points)

    @property
    def resolved(self) -> bool:
        return self.surface is not None

    def _need_surface(self) -> SurfacePoints:
        if self.surface is None:
            raise ValueError("body stroke not resolved onto a surface yet (use resolve_strokes)")
        return self.surface

    @property
    def surface_points(self) -> np.ndarray:
        """(n, 3) float64 metres: the stroke's points on the surface (resolved strokes only)."""
        return self._need_surface().points

    @property
    def faces(self) -> np.ndarray:
        """(n,) int64: the surface face under each point (resolved strokes only)."""
        return self._need_surface().faces

    @property
    def barycentric(self) -> np.ndarray:
        """(n, 3) float64: barycentric coordinates of each point in its face (resolved strokes only)."""
        return self._need_surface().barycentric

    @property
    def length_m(self) -> float:
        """Length of the resolved stroke's polyline through its surface points, metres."""
        return float(arc_length(self.surface_points)[-1])

    def resample(self, surface: TriMesh | Surface, k: int, *, step_m: float = 0.005) -> SurfacePoints:
        """k surface points equally spaced by arc length along the path the resolved stroke traces on
        `surface` (densified to `step_m` and projected, so it follows the surface between sparse points)."""
        return resample_on_surface(Surface.of(surface), self.surface_points, k, step_m=step_m)


@dataclass(eq=False)
class StrokePair:
    """A pattern stroke and the body stroke it goes onto. id : the number both carry (an int)."""

    id: int
    pattern: PatternStroke
    body: BodyStroke


@dataclass(eq=False)
class Strokes:
    """All the stroke pairs of a dressing, in drawing order.

    Attributes
    ----------
    pairs : list of StrokePair, ids unique.
    target : "body" (dress the body) or "garment" (re-wrap: the body strokes lie on a garment already on
        the body).
    meta : free-form JSON-serialisable notes, kept through files.
    source : the file the strokes came from (named in error messages), "" if none.
    """

    pairs: list[StrokePair] = field(default_factory=list)
    target: Target = "body"
    meta: dict[str, Any] = field(default_factory=dict)
    source: str = ""

    def __post_init__(self) -> None:
        if self.target not in ("body", "garment"):
            raise InputError(f"target must be 'body' or 'garment', got {self.target!r}", self.source or None)
        seen: dict[int, int] = {}
        for k, p in enumerate(self.pairs):
            if p.id in seen:
                raise InputError(f"stroke id {p.id} is used twice (pairs {seen[p.id]} and {k})", self.source or None)
            seen[p.id] = k

    def __len__(self) -> int:
        return len(self.pairs)

    @property
    def ids(self) -> list[int]:
        return [p.id for p in self.pairs]

    def pair(self, id: int) -> StrokePair:
        """The pair with this id (KeyError if none)."""
        for p in self.pairs:
            if p.id == id:
                return p
        raise KeyError(id)

    @property
    def resolved(self) -> bool:
        """Every body stroke has its surface points."""
        return all(p.body.resolved for p in self.pairs)


# -- files ---------------------------------------------------------------------------------------------------
def _kind(v: Any) -> str:
    return {dict: "an object", list: "a list", str: "a string", bool: "true/false", type(None): "null"}.get(
        type(v), "a number"
    )


def _object(v: Any, ctx: str) -> dict:
    if not isinstance(v, dict):
        raise InputError(f"{ctx}: expected an object, got {_kind(v)}")
    return v


def _context(ctx: str, fn, *args):
    try:
        return fn(*args)
    except InputError as e:
        raise InputError(f"{ctx}: {e.message}") from None


def _pair_from_dict(d: Any, k: int) -> StrokePair:
    d = _object(d, f"pairs[{k}]")
    if "id" not in d:
        raise InputError(f"pairs[{k}]: missing field 'id'")
    sid = d["id"]
    if isinstance(sid, bool) or not isinstance(sid, int):
        raise InputError(f"pairs[{k}]: id must be an integer, got {sid!r}")
    ctx = f"stroke {sid}"
    pat, body = d.get("pattern"), d.get("body")
    if pat is None and body is None:
        raise InputError(f"{ctx}: has neither a pattern stroke nor a body stroke")
    if body is None:
        raise InputError(f"{ctx}: has a pattern stroke but no body stroke (unmatched id)")
    if pat is None:
        raise InputError(f"{ctx}: has a body stroke but no pattern stroke (unmatched id)")
    pat = _object(pat, f"{ctx}: pattern")
    if "piece" not in pat or "points" not in pat:
        raise InputError(f"{ctx}: pattern stroke needs 'piece' and 'points'")
    pattern = _context(ctx, PatternStroke, pat["piece"], pat["points"])
    body = _object(body, f"{ctx}: body")
    if ("points" in body) == ("laser" in body):
        raise InputError(f"{ctx}: body stroke needs exactly one of 'points' and 'laser'")
    if "points" in body:
        bstroke = _context(ctx, BodyStroke, body["points"])
    else:
        laser = _object(body["laser"], f"{ctx}: body.laser")
        if "rays" not in laser:
            raise InputError(f"{ctx}: laser stroke needs 'rays' (origin xyz, direction xyz per ray)")
        hit = laser.get("hit", "first")
        if hit not in ("first", "last"):
            raise InputError(f"{ctx}: laser hit must be 'first' or 'last', got {hit!r}")
        bstroke = _context(ctx, BodyStroke, None, laser["rays"], hit)
    return StrokePair(sid, pattern, bstroke)


def strokes_from_dict(d: Any) -> Strokes:
    """Strokes from the parsed JSON of a strokes file; InputError (without a file name) when malformed."""
    if not isinstance(d, dict):
        raise InputError(f"not a kitsuke strokes file (the top level is {_kind(d)}, expected an object)")
    fmt = d.get("format")
    if fmt != FORMAT:
        raise InputError(f"not a kitsuke strokes file (format is {fmt!r}, expected {FORMAT!r})")
    if d.get("version") != VERSION:
        raise InputError(f"unsupported {FORMAT} version {d.get('version')!r} (this kitsuke reads version {VERSION})")
    target = d.get("target", "body")
    if target not in ("body", "garment"):
        raise InputError(f"target must be 'body' or 'garment', got {target!r}")
    pairs = d.get("pairs")
    if not isinstance(pairs, list):
        raise InputError(f"'pairs' must be a list of stroke pairs, got {_kind(pairs)}")
    meta = d.get("meta", {})
    if not isinstance(meta, dict):
        raise InputError(f"'meta' must be an object, got {_kind(meta)}")
    limits.check("strokes", len(pairs), f"the file has {len(pairs):,} stroke pairs")
    return Strokes([_pair_from_dict(p, k) for k, p in enumerate(pairs)], target, dict(meta))


def _rows(a: np.ndarray) -> list[list[float]]:
    return [[float(x) for x in row] for row in a]


def strokes_to_dict(strokes: Strokes) -> dict[str, Any]:
    """The JSON-ready dict of a strokes file. Body strokes are written as given (points or laser rays), not as
    their resolved surface points."""
    pairs = []
    for p in strokes.pairs:
        b = p.body
        body = {"points": _rows(b.points)} if b.points is not None else {"laser": {"rays": _rows(b.rays), "hit": b.hit}}
        pairs.append(
            {
                "id": p.id,
                "pattern": {"piece": p.pattern.piece, "points": _rows(p.pattern.points)},
                "body": body,
            }
        )
    out: dict[str, Any] = {"format": FORMAT, "version": VERSION, "target": strokes.target, "pairs": pairs}
    if strokes.meta:
        out["meta"] = strokes.meta
    return out


def read_strokes(path: str | os.PathLike[str]) -> Strokes:
    """Read a kitsuke strokes file, its structure checked (`check_strokes`, `resolve_strokes` do the rest)."""
    d = read_json(path, what="strokes file")
    try:
        strokes = strokes_from_dict(d)
    except InputError as e:
        raise InputError(e.message, path) from None
    strokes.source = str(path)
    return strokes


_NUMBER_LIST = re.compile(r"\[\s*(-?[0-9][0-9.eE+-]*(?:,\s*-?[0-9][0-9.eE+-]*)*)\s*\]")


def strokes_to_json(strokes: Strokes) -> str:
    """The text of a strokes file: indented JSON with each point on one line (easy to read and edit)."""
    text = json.dumps(strokes_to_dict(strokes), indent=1, allow_nan=False, ensure_ascii=False)
    return _NUMBER_LIST.sub(lambda m: "[" + ", ".join(x.strip() for x in m.group(1).split(",")) + "]", text) + "\n"


def write_strokes(strokes: Strokes, path: str | os.PathLike[str]) -> None:
    """Write `strokes` as a kitsuke strokes v1 file, atomically."""
    write_text_atomic(path, strokes_to_json(strokes))


# -- checks against the pattern and the surface --------------------------------------------------------------
def triangles_crossed(pattern_mesh: PatternMesh, stroke: PatternStroke) -> np.ndarray:
    """Faces of `pattern_mesh` (indices into `pattern_mesh.faces`, sorted, int64) that the pattern stroke's
    polyline crosses or touches, within its piece. Empty if the piece is not in the mesh."""
    if stroke.piece not in pattern_mesh.piece_names:
        return np.zeros(0, np.int64)
    k = pattern_mesh.piece_names.index(stroke.piece)
    f0, f1 = (int(x) for x in pattern_mesh.piece_faces[k])
    tri = pattern_mesh.vertices_cm[pattern_mesh.faces[f0:f1]]
    _, faces = segments_cross_triangles(stroke.points, tri)
    return np.unique(faces) + f0


def in_piece_frame(strokes: Strokes, pattern: Pattern) -> Strokes:
    """`strokes` with every pattern stroke moved from the coordinates of the pattern's file (what a user draws
    on: GarmentCode's own panel coordinates) to the piece's own (`Pattern.file_to_piece`); the same object when
    no piece differs."""
    if not any(p.pattern.piece in pattern.file_mirrored for p in strokes.pairs):
        return strokes
    pairs = [
        dataclasses.replace(
            p, pattern=PatternStroke(p.pattern.piece, pattern.file_to_piece(p.pattern.piece, p.pattern.points))
        )
        for p in strokes.pairs
    ]
    return Strokes(pairs, strokes.target, dict(strokes.meta), strokes.source)


def in_file_frame(strokes: Strokes, pattern: Pattern) -> Strokes:
    """The inverse of `in_piece_frame`: strokes as a user would write them for the pattern's file."""
    return in_piece_frame(strokes, pattern)  # a mirror is its own inverse


def check_strokes(strokes: Strokes, pattern: Pattern, *, pattern_mesh: PatternMesh | None = None) -> None:
    """Check the pattern side of every stroke; InputError naming the strokes file and the stroke id.

    Pattern points are in the coordinates of the pattern's file (`in_piece_frame`). Each pattern stroke must
    name a piece of `pattern` that is not a sliver (the wrap leaves those out: `slivers_left_out`); its
    points, and its path sampled every 0.5 cm, must lie on the piece (curved edges included) to within 1 mm; given
    `pattern_mesh`, it must cross at least one triangle of its piece there.
    """
    _check_on_pieces(in_piece_frame(strokes, pattern), pattern, pattern_mesh)


def slivers_left_out(strokes: Strokes, pattern: Pattern) -> dict[str, float]:
    """{name: mean width cm} of the pieces the wrap leaves out of `pattern`: its slivers
    (`kitsuke.pattern.sliver_pieces`), unless it has nothing else (then it is wrapped whole). InputError for the
    first stroke drawn on one."""
    thin = sliver_pieces(pattern)
    if len(thin) == len(pattern.pieces):
        return {}
    for pair in strokes.pairs:
        if pair.pattern.piece in thin:
            raise InputError(
                f"stroke {pair.id} is drawn on piece {pair.pattern.piece!r}, a sliver "
                f"{thin[pair.pattern.piece] * 10:.2g} mm wide that the wrap leaves out: draw it on a neighbour",
                strokes.source or None,
            )
    return thin


def _check_on_pieces(strokes: Strokes, pattern: Pattern, pattern_mesh: PatternMesh | None) -> None:
    """`check_strokes` for strokes already in the pieces' own coordinates."""
    slivers_left_out(strokes, pattern)
    path = strokes.source or None
    polygons: dict[str, np.ndarray] = {}
    for pair in strokes.pairs:
        ps, ctx = pair.pattern, f"stroke {pair.id}"
        if ps.piece not in pattern.piece_names:
            names = ", ".join(pattern.piece_names)
            raise InputError(f"{ctx}: pattern piece {ps.piece!r} is not in pattern {pattern.name!r} ({names})", path)
        if ps.piece not in polygons:
            polygons[ps.piece] = pattern.piece(ps.piece).polygon()
        poly = polygons[ps.piece]
        out = ~polygon_inside(ps.points, poly) & (polygon_distance(ps.points, poly) > PIECE_TOLERANCE_CM)
        if out.any():
            i = int(np.argmax(out))
            x, y = ps.points[i]
            d = polygon_distance(ps.points[i : i + 1], poly)[0]
            raise InputError(
                f"{ctx}: pattern point {i} ({x:.1f}, {y:.1f}) cm lies {d:.1f} cm outside piece {ps.piece!r}",
                path,
            )
        dense = densify_polyline(ps.points, PIECE_CHECK_STEP_CM)
        out = ~polygon_inside(dense, poly) & (polygon_distance(dense, poly) > PIECE_TOLERANCE_CM)
        if out.any():
            # Which drawn segment the first outside sample belongs to.
            seg = int(np.searchsorted(arc_length(ps.points), arc_length(dense)[int(np.argmax(out))], side="right"))
            seg = min(max(seg - 1, 0), len(ps.points) - 2)
            raise InputError(
                f"{ctx}: pattern stroke leaves piece {ps.piece!r} between points {seg} and {seg + 1}", path
            )
        if pattern_mesh is not None:
            if ps.piece not in pattern_mesh.piece_names:
                raise InputError(f"{ctx}: piece {ps.piece!r} is not in the meshed pattern", path)
            if not len(triangles_crossed(pattern_mesh, ps)):
                raise InputError(f"{ctx}: pattern stroke crosses no triangle of piece {ps.piece!r}", path)


def resolve_strokes(
    strokes: Strokes,
    pattern: Pattern,
    surface: TriMesh | Surface,
    *,
    pattern_mesh: PatternMesh | None = None,
    max_distance_m: float = MAX_SURFACE_DISTANCE_M,
) -> Strokes:
    """Check `strokes` against the pattern (`check_strokes`) and put every body stroke on `surface`.

    surface : the body's skin (target "body") or the dressed garment (target "garment"), metres; a `Surface`
        reuses its acceleration structures across calls.
    Drawn points go to their closest surface point (libigl AABB) and must lie within `max_distance_m` of it;
    laser rays take their first or last hit (embree) and must hit. Returns a new Strokes whose body strokes
    have `surface` filled in and whose pattern strokes are in the pieces' own coordinates (`in_piece_frame`);
    raises InputError naming the strokes file and the stroke id.
    """
    strokes = in_piece_frame(strokes, pattern)
    _check_on_pieces(strokes, pattern, pattern_mesh)
    return strokes_on_surface(strokes, surface, max_distance_m=max_distance_m)


def strokes_on_surface(
    strokes: Strokes, surface: TriMesh | Surface, *, max_distance_m: float = MAX_SURFACE_DISTANCE_M
) -> Strokes:
    """The 3D side of `resolve_strokes` alone (no pattern check): every body stroke put on `surface`."""
    if not (math.isfinite(max_distance_m) and max_distance_m > 0):
        raise ValueError("max_distance_m must be a positive number of metres")
    surf = Surface.of(surface)
    path = strokes.source or None
    what = "body" if strokes.target == "body" else "garment"
    resolved: dict[int, SurfacePoints] = {}
    # One closest-point query for all drawn points, one ray cast per hit kind.
    drawn = [p for p in strokes.pairs if not p.body.is_laser]
    if drawn:
        sp = surf.closest(np.vstack([p.body.points for p in drawn]))
        start = 0
        for p in drawn:
            part = sp.take(np.arange(start, start + p.body.n_points))
            start += p.body.n_points
            far = part.distance > max_distance_m
            if far.any():
                i = int(np.argmax(far))
                raise InputError(
                    f"stroke {p.id}: body point {i} is {part.distance[i] * 100:.1f} cm from the {what} "
                    f"surface (at most {max_distance_m * 100:g} cm)",
                    path,
                )
            resolved[p.id] = part
    for hit in ("first", "last"):
        lasers = [p for p in strokes.pairs if p.body.is_laser and p.body.hit == hit]
        if not lasers:
            continue
        rays = np.vstack([p.body.rays for p in lasers])
        sp = surf.cast(rays[:, :3], rays[:, 3:], hit=hit)
        start = 0
        for p in lasers:
            part = sp.take(np.arange(start, start + p.body.n_points))
            start += p.body.n_points
            if not part.hit.all():
                i = int(np.argmax(~part.hit))
                raise InputError(f"stroke {p.id}: laser ray {i} hits nothing on the {what} surface", path)
            resolved[p.id] = part
    pairs = []
    for p in strokes.pairs:
        sp = resolved[p.id]
        if arc_length(sp.points)[-1] < MIN_SURFACE_LENGTH_M:
            raise InputError(
                f"stroke {p.id}: body stroke has zero length on the {what} surface (its points land on one spot)",
                path,
            )
        pairs.append(StrokePair(p.id, p.pattern, dataclasses.replace(p.body, surface=sp)))
    return Strokes(pairs, strokes.target, dict(strokes.meta), strokes.source)
