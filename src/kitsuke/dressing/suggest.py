"""Suggested strokes: a stroke set proposed from the placement a pattern carries, for a user to start from.

    from kitsuke.dressing import suggest_strokes
    strokes = suggest_strokes(body, pattern)          # Strokes, pattern points in the pattern file's coordinates

GarmentCode places every panel around its body, the kimono generator hangs its pieces as on a kimono stand. For each
piece large enough to matter (`SuggestParams.min_area_share`, `min_area_cm2`; smaller ones, cuffs and waistbands,
follow their seams), the pattern stroke runs along the piece's long axis through its middle, kept off its edges.
Each of its points is carried to the body along the placed piece's normal (the body point nearest the placed point
on that line, within `reach_m`), which keeps a sleeve's stroke on its arm where a nearest-point search would jump to
the torso. The longest run of points that the body continues without a jump becomes the body stroke, and the longer
of the two strokes is trimmed about its middle so that both have the same length. Last, the garment is wrapped once
on these strokes and each body stroke moves to where its pattern stroke came to rest (`settled_strokes`): a
placement is a layout, not where the sewn garment hangs. A garment that rests there tighter than the body round it
(GarmentCode lays a skirt cut for the waist at the hips) is raised until it fits, its strokes with it (`_fit_height`).

Two fallbacks, both after the carry along the normal (so a sleeve that reaches its arm keeps its stroke there):

- when no large piece reaches the body, the smaller ones are tried, largest first, the share rule then holding
  among those that reach it (a dress whose bodice GarmentCode laid on the body and whose skirt it laid far out);
- a large piece laid out far from the body (GarmentCode's ring of skirt panels 1-2 m out) is drawn in to it by
  its seams to the pieces near it (`_far_pieces`) and carried from there, only as far as `drawn_in_reach_m` and
  `drawn_in_below_m` keep it: from its waist seam over the hips, where the body holds a hanging skirt.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..errors import InputError
from ..geometry.mesh import TriMesh
from ..geometry.surface import Surface
from ..pattern import Pattern, Piece
from ._far_pieces import drawn_in_placements
from ._fit_height import fitting_lift
from ._polyline import arc_length, interpolate_polyline, polygon_distance, polygon_grid, polygon_inside
from .strokes import BodyStroke, PatternStroke, StrokePair, Strokes

#: Grid cells across a piece's bounding box when its area moments are sampled.
MOMENT_GRID = 48
#: Most settles of a garment resting tighter than the body, each followed by a raise (`settled_strokes`).
FIT_ROUNDS = 2


@dataclass(frozen=True)
class SuggestParams:
    """Options of `suggest_strokes`.

    min_area_share, min_area_cm2 : a piece gets a stroke when its area is at least this share of the largest
        piece's, or at least min_area_cm2 (cm²): a bodice's panels beside a skirt ten times their size (GarmentCode's
        circle skirts) are held by strokes of their own, not grown from the skirt's.
    margin_cm : the pattern stroke stays this far inside its piece's outline, cm.
    trim : share of the inside chord left out at each end (strokes drawn by hand stop short of the edges).
    step_cm : spacing of the stroke points, cm.
    reach_m : a placed point is carried at most this far along the piece's normal to the body, metres.
    jump_m : consecutive body points farther apart than this plus twice `step_cm` break the stroke (the line
        ran off one limb onto another), metres.
    min_length_cm : shorter strokes are not suggested, cm.
    drawn_in_reach_m : a large piece laid out far from the body (no point of it reaches it along its normal) is
        drawn in to it (`_far_pieces`) and carried at most this far, metres: the part of it the body holds.
    drawn_in_below_m : ... and no lower than this below where it first touched the body, metres (a skirt panel
        drawn in touches the hips and hangs free below them; a hand draws a little past the widest point).
    settle : move each body stroke to where its pattern stroke rests once the garment, wrapped on the strokes
        from the placement, has settled (`settled_strokes`), so the strokes ask for what the garment can give.
    fit : with `settle`, raise a garment that rests tighter than the body round it until it fits
        (`_fit_height.fitting_lift`), its body strokes with it.
    """

    min_area_share: float = 0.15
    min_area_cm2: float = 500.0
    margin_cm: float = 2.0
    trim: float = 0.15
    step_cm: float = 2.0
    reach_m: float = 0.35
    jump_m: float = 0.02
    min_length_cm: float = 6.0
    drawn_in_reach_m: float = 0.06
    drawn_in_below_m: float = 0.10
    settle: bool = True
    fit: bool = True

    def __post_init__(self) -> None:
        if not (
            0 <= self.min_area_share <= 1
            and self.min_area_cm2 >= 0
            and self.margin_cm >= 0
            and 0 <= self.trim < 0.5
            and self.step_cm > 0
            and self.reach_m > 0
            and self.jump_m >= 0
            and self.min_length_cm > 0
            and self.drawn_in_reach_m > 0
            and self.drawn_in_below_m >= 0
        ):
            raise InputError(
                "suggest parameters: 0 <= min_area_share <= 1, min_area_cm2 >= 0, margin_cm >= 0, 0 <= trim < 0.5, "
                "step_cm > 0, reach_m > 0, jump_m >= 0, min_length_cm > 0, drawn_in_reach_m > 0, "
                "drawn_in_below_m >= 0 required"
            )


def _downwards(axis: np.ndarray) -> np.ndarray:
    """A direction (2,) as a hand draws it: down a panel, or left to right when it runs across."""
    if abs(axis[1]) >= abs(axis[0]):
        return axis if axis[1] < 0 else -axis
    return axis if axis[0] > 0 else -axis


def stroke_through(piece: Piece, point: np.ndarray, axis: np.ndarray, params: SuggestParams) -> np.ndarray | None:
    """(n, 2) cm: the stroke along `axis` through `point` of the piece, `margin_cm` inside its outline (at most a
    quarter of its width across `axis`; the inside run nearest `point`) and trimmed by `trim` at each end; None
    when it is shorter than `min_length_cm`."""
    poly = piece.polygon()
    reach = float(np.linalg.norm(np.ptp(poly, axis=0)))
    # A narrow piece (a band a few cm wide) keeps a quarter of its width clear on each side instead.
    margin = min(params.margin_cm, 0.25 * float(np.ptp(poly @ np.array([-axis[1], axis[0]]))))
    t = np.arange(-reach, reach, 0.25)
    line = point + t[:, None] * axis
    ok = polygon_inside(line, poly) & (polygon_distance(line, poly) >= margin)
    if not ok.any():
        return None
    runs = np.flatnonzero(np.diff(np.r_[0, ok.astype(np.int8), 0])).reshape(-1, 2)
    mid = int(np.argmin(np.abs(t)))
    best = min(runs, key=lambda r: 0 if r[0] <= mid < r[1] else min(abs(r[0] - mid), abs(r[1] - 1 - mid)))
    a, b = t[best[0]], t[best[1] - 1]
    cut = params.trim * (b - a)
    a, b = a + cut, b - cut
    if b - a < params.min_length_cm:
        return None
    n = max(2, int(np.ceil((b - a) / params.step_cm)) + 1)
    return point + np.linspace(a, b, n)[:, None] * axis


def candidate_strokes(piece: Piece, params: SuggestParams) -> list[np.ndarray]:
    """Pattern strokes (n, 2) cm worth trying on a piece, best first: along its long axis (the principal axis of
    its area) and, on a placed piece, along the world's vertical, each through its centroid and through points
    across it (a dart through the centroid, or a side that wraps out of reach, spoils one line, not all)."""
    inside = polygon_grid(piece.polygon(), MOMENT_GRID)
    if len(inside) < 3:
        return []
    centre = inside.mean(axis=0)
    _, vecs = np.linalg.eigh(np.cov((inside - centre).T))
    axes = [_downwards(vecs[:, -1])]
    if piece.placement is not None:
        up = piece.placement.matrix[1, :2]  # the world's Y in piece coordinates (ignoring any fold)
        if np.linalg.norm(up) > 0.5:
            vertical = _downwards(up / np.linalg.norm(up))
            if abs(float(vertical @ axes[0])) < 0.97:
                axes.append(vertical)
    out = []
    for axis in axes:
        across = np.array([-axis[1], axis[0]])
        width = float(np.ptp(inside @ across))
        for shift in (0.0, -0.2, 0.2, -0.35, 0.35):
            stroke = stroke_through(piece, centre + shift * width * across, axis, params)
            if stroke is not None:
                out.append(stroke)
    return out


def _placed_normals(piece: Piece, pts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """World points (n, 3) metres of piece points (n, 2) cm and the placed piece's outer normals there (n, 3)
    (by finite differences, so a folded placement bends them over its fold)."""
    pl = piece.placement
    x = pl.apply(pts)
    du = pl.apply(pts + [0.5, 0.0]) - x
    dv = pl.apply(pts + [0.0, 0.5]) - x
    n = np.cross(du, dv)  # counter-clockwise seen from the outer face: local x, y, z right-handed
    return x, n / np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-300)


def carry_to_body(surface: Surface, points: np.ndarray, normals: np.ndarray, reach_m: float) -> np.ndarray:
    """(n, 3) metres: for each placed point, the body point nearest it on the line along its normal, within
    `reach_m` on either side; NaN where the line meets the body nowhere that close."""
    origins = points + reach_m * normals
    ray, hits = surface.ray_hits(origins, -normals)
    out = np.full_like(points, np.nan)
    if not len(ray):
        return out
    gap = np.abs(hits.distance - reach_m)
    order = np.lexsort((gap, ray))
    first = order[np.r_[True, ray[order][1:] != ray[order][:-1]]]
    keep = first[gap[first] <= reach_m]
    out[ray[keep]] = hits.points[keep]
    return out


def _longest_run(ok: np.ndarray) -> tuple[int, int]:
    """[start, stop) of the longest run of True in a boolean (n,) array; (0, 0) if none."""
    edges = np.flatnonzero(np.diff(np.r_[0, ok.astype(np.int8), 0])).reshape(-1, 2)
    if not len(edges):
        return 0, 0
    k = int(np.argmax(edges[:, 1] - edges[:, 0]))
    return int(edges[k, 0]), int(edges[k, 1])


def _trim_to(points: np.ndarray, length: float) -> np.ndarray:
    """The middle part of a polyline (n, d), `length` long (in its units), with as many points."""
    total = float(arc_length(points)[-1])
    mid = 0.5 * total
    return interpolate_polyline(points, np.linspace(mid - 0.5 * length, mid + 0.5 * length, len(points)))


def suggest_pair(
    piece: Piece, surface: Surface, params: SuggestParams, *, lowest_m: float | None = None
) -> tuple[np.ndarray, np.ndarray] | None:
    """One stroke pair for a placed piece: (pattern points (n, 2) cm in the piece's own coordinates, body points
    (n, 3) metres on the surface), as long as each other: of `candidate_strokes`, the one whose longest part
    reaches the body; None when none does. lowest_m : placed points below this height (metres) are not carried."""
    best, best_length = None, params.min_length_cm
    for pat in candidate_strokes(piece, params):
        placed, normals = _placed_normals(piece, pat)
        on = carry_to_body(surface, placed, normals, params.reach_m)
        ok = np.isfinite(on).all(axis=1)
        if lowest_m is not None:
            ok &= placed[:, 1] >= lowest_m
        step = np.linalg.norm(np.diff(np.where(ok[:, None], on, 0.0), axis=0), axis=1)
        joined = ok[:-1] & ok[1:] & (step <= params.jump_m + 2e-2 * params.step_cm)
        a, b = _longest_run(joined)  # points a..b: every link between them joined
        if b <= a:
            continue
        p_run, b_run = pat[a : b + 1], on[a : b + 1]
        lp, lb = float(arc_length(p_run)[-1]), float(arc_length(b_run)[-1]) * 100.0
        if min(lp, lb) < best_length + 1.0:  # a longer candidate must win by a centimetre
            continue
        best, best_length = (p_run, b_run, lp, lb), min(lp, lb)
    if best is None:
        return None
    pat, body, lp, lb = best
    if lb > lp:
        body = _trim_to(body, lp / 100.0)
    else:
        pat = _trim_to(pat, lb)
    return pat, surface.closest(body).points


def _smaller_pairs(pieces: list[Piece], surface: Surface, params: SuggestParams) -> dict:
    """Stroke pairs (`suggest_pair`) by piece name for pieces below the share rule, tried largest first, when no
    piece above it reached the body: the share rule then holds among the pieces that do (GarmentCode lays a
    dress's bodice on the body and its skirt panels, each eight times the bodice's pieces, far out)."""
    out, first = {}, None
    for piece in pieces:
        if first is not None and piece.area < min(params.min_area_share * first, params.min_area_cm2):
            break
        got = suggest_pair(piece, surface, params)
        if got is not None:
            out[piece.name] = got
            first = piece.area if first is None else first
    return out


def suggest_strokes(
    body,
    pattern: Pattern,
    *,
    params: SuggestParams | None = None,
    surface: Surface | None = None,
) -> Strokes:
    """A stroke set for `pattern` on `body` from the pattern's placement (module docstring).

    body : a `kitsuke.body.Body` or a TriMesh, metres, in the frame the placement was made for.
    pattern : a Pattern whose pieces carry placements (GarmentCode's, the kimono generator's).
    Returns Strokes (target "body"), one pair per piece that got a stroke, largest piece first, pattern points in
    the coordinates of the pattern's file (as a user draws them). Raises InputError when no piece has a
    placement, or when no stroke can be carried to the body (the placement was made for another body).
    """
    p = params or SuggestParams()
    placed = [pc for pc in pattern.pieces if pc.placement is not None]
    if not placed:
        raise InputError(
            f"pattern {pattern.name!r} carries no placement: strokes can only be suggested for a pattern that says "
            "where its pieces go (GarmentCode's, a kimono from `kitsuke pattern kimono`); draw them instead"
        )
    mesh = body if isinstance(body, TriMesh) else body.mesh
    surf = surface if surface is not None else Surface(mesh)
    by_size = sorted(placed, key=lambda pc: -pc.area)
    big = [pc for pc in by_size if pc.area >= min(p.min_area_share * by_size[0].area, p.min_area_cm2)]
    found = {pc.name: suggest_pair(pc, surf, p) for pc in big}
    if not any(found.values()):
        found.update(_smaller_pairs(by_size[len(big) :], surf, p))
    missed = [pc.name for pc in big if found[pc.name] is None]
    if missed:
        # A piece drawn in from far (a skirt panel) lies on the body from where it is sewn (the waist) down to
        # where it touches it (the hips), and hangs free below: its whole line is tried, and only that part kept.
        drawn = replace(p, trim=0.0, reach_m=min(p.reach_m, p.drawn_in_reach_m))
        for name, (moved, touch_y) in drawn_in_placements(pattern, missed, surf, p.reach_m).items():
            piece = pattern.piece(name).copy()
            piece.placement = moved
            found[name] = suggest_pair(piece, surf, drawn, lowest_m=touch_y - p.drawn_in_below_m)
    pairs: list[StrokePair] = []
    for piece in by_size:
        got = found.get(piece.name)
        if got is None:
            continue
        pat, on = got
        pairs.append(
            StrokePair(
                len(pairs) + 1,
                PatternStroke(piece.name, np.round(pattern.piece_to_file(piece.name, pat), 2)),
                BodyStroke(points=np.round(on, 4)),
            )
        )
    if not pairs:
        raise InputError(
            f"no stroke of pattern {pattern.name!r} reaches the body along its placement: its pieces are too small "
            f"for a {p.min_length_cm:g} cm stroke, or the placement was made for another body (or in other units)"
        )
    meta = {"made_by": "kitsuke strokes suggest", "pattern": pattern.name, "settled": False}
    strokes = Strokes(pairs, "body", meta)
    return settled_strokes(body, pattern, strokes, surf, fit=p.fit) if p.settle else strokes


def settled_strokes(body, pattern: Pattern, strokes: Strokes, surface: Surface, *, fit: bool = True) -> Strokes:
    """`strokes` with each body stroke moved to where its pattern stroke lies once the garment has settled on
    them (a quick wrap: no polish, strokes not held after the settle); `strokes` as they are when that wrap
    fails. A placement is a layout around the body, not where the sewn garment rests: GarmentCode lays a crop top's
    panels flat in front of and behind the body, and sewn over the shoulders it rides 7-10 cm higher, where
    strokes drawn on the layout cannot hold it without tearing (190 % max strain held there).
    fit : a garment that rests tighter than the body round it has its strokes raised by `fitting_lift` from where
    its cloth rests; it is then settled again on them, and raised again from there if it still needs it, for at
    most `FIT_ROUNDS` settles. The last raise is kept as it is: a settle does not hold the strokes, and a skirt
    slides back down part of the way in it (a godet skirt raised 4 cm rose 1 cm)."""
    from ..errors import ComputationError
    from .wrap import WrapParams, wrap

    quick = WrapParams().changed({"polish.rounds": 0, "tethers.reach_m": None})
    raised, out = 0.0, strokes
    for _ in range(FIT_ROUNDS if fit else 1):
        try:
            g = wrap(body, pattern, out, params=quick, report=False, check=False)
        except (ComputationError, InputError):
            break
        if not np.isfinite(g.positions).all():
            break
        lift = fitting_lift(g.positions, g.faces, g.model.rest_corners, surface) if fit else 0.0
        pairs = []
        for pair, track in zip(out.pairs, g.tracks, strict=True):
            on = surface.closest(track.points(g.positions, g.faces) + [0.0, lift, 0.0]).points
            if track.reversed:
                on = on[::-1]
            pairs.append(StrokePair(pair.id, pair.pattern, BodyStroke(points=np.round(on, 4))))
        raised += lift
        out = Strokes(pairs, "body", {**strokes.meta, "settled": True, "raised_m": round(raised, 3)})
        if not lift:
            break
    return out
