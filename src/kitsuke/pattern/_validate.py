"""Pattern validation: what is an error (the pattern cannot be used) and what is a warning (it can, but look).

Errors — a loader refuses the file (InputError naming it) and `validate` lists them with severity "error":
  no-pieces, duplicate-name, zero-length-edge (two equal consecutive outline points), zero-area,
  self-intersection (the outline, curves included, crosses or touches itself), clockwise (the outline must run
  counter-clockwise seen from the outer face; reverse it or set `flipped`), unknown-piece, unknown-edge,
  seam-self (an edge sewn to itself), edge-in-two-seams (a seam joins whole edges; split the edge instead),
  bad-layers (a malformed `meta["layers"]`, see `_layers`), over-limit (more pieces or seams than
  `kitsuke.limits` allows; a piece past the size limits is refused when it is made).
Warnings — reported, the pattern loads and meshes:
  length-mismatch (a seam's two edges differ by more than 1 % of the longer one: sewing would stretch or ease
  the cloth; meshing still gives both sides the same number of vertices), sliver (a piece narrower on average
  than `SLIVER_CM`: its mesh is a row of needle triangles, and in a wrap its two long sides act as one seam).
"""

from __future__ import annotations

import os
from collections import Counter
from dataclasses import dataclass
from typing import Literal

import numpy as np

from .. import limits
from ..errors import InputError
from . import _geometry as geo
from ._layers import pattern_layers
from ._types import EdgeRef, Pattern

#: Relative length difference above which a seam is reported.
LENGTH_TOLERANCE = 0.01
#: Area below this fraction of the squared outline size counts as zero.
ZERO_AREA_FRACTION = 1e-9
#: Chord tolerance (cm) of the densified outline used for the self-intersection test.
INTERSECTION_TOL_CM = 0.02
#: A piece whose mean width (twice its area over its perimeter: a strip's width) is below this is a sliver, cm.
#: GarmentCode's sampler makes such cuffs on short trousers (0.25 mm tall, 18.6 cm long), which tore in the wrap.
SLIVER_CM = 0.5


@dataclass(frozen=True)
class Issue:
    """One finding of `validate`.

    Attributes
    ----------
    severity : "error" (the pattern cannot be used) or "warning".
    code : a stable short name, e.g. "length-mismatch" (see the module docstring for the list).
    message : one line for people.
    piece : the piece concerned, if one.
    seam : index of the seam concerned, if one.
    edges : the edges of `piece` at fault (a crossing's two edges, a zero-length edge), for showing on the piece.
    """

    severity: Literal["error", "warning"]
    code: str
    message: str
    piece: str | None = None
    seam: int | None = None
    edges: tuple[int, ...] = ()

    def to_dict(self) -> dict:
        d = {"severity": self.severity, "code": self.code, "message": self.message}
        if self.piece is not None:
            d["piece"] = self.piece
        if self.seam is not None:
            d["seam"] = self.seam
        if self.edges:
            d["edges"] = list(self.edges)
        return d


def _piece_issues(piece) -> list[Issue]:
    out: list[Issue] = []
    name = piece.name
    pts = piece.outline
    step = np.linalg.norm(pts - np.roll(pts, -1, axis=0), axis=1)
    size = float(np.ptp(pts, axis=0).max())
    for i in np.flatnonzero(step <= 1e-9 * max(size, 1.0)):
        out.append(
            Issue(
                "error",
                "zero-length-edge",
                f"piece {name!r}: edge {i} has zero length (repeated point)",
                name,
                edges=(int(i),),
            )
        )
    if out:
        return out  # the geometry below would be meaningless
    poly, edge_of = piece.polygon_with_edges(tol_cm=INTERSECTION_TOL_CM)
    area = geo.signed_area(poly)
    hit = geo.self_intersections(poly)
    if hit is not None:
        edges = sorted({int(edge_of[hit[0]]), int(edge_of[hit[1]])})
        where = f"edges {edges[0]} and {edges[1]}" if len(edges) == 2 else f"edge {edges[0]}"
        out.append(
            Issue("error", "self-intersection", f"piece {name!r}: outline crosses itself ({where})", name,
                  edges=tuple(edges))
        )  # fmt: skip
    elif abs(area) <= ZERO_AREA_FRACTION * size * size:
        out.append(Issue("error", "zero-area", f"piece {name!r}: outline has zero area", name))
    elif area < 0:
        out.append(
            Issue(
                "error",
                "clockwise",
                f"piece {name!r}: outline runs clockwise; kitsuke outlines run counter-clockwise seen from the "
                "outer face (reverse the points, or set flipped)",
                name,
            )
        )
    else:
        width, perimeter = _mean_width(poly, area)
        if width < SLIVER_CM:
            out.append(
                Issue(
                    "warning",
                    "sliver",
                    f"piece {name!r}: {width * 10:.2g} mm wide on average ({area:.2g} cm² over "
                    f"{perimeter / 2:.3g} cm): a sliver whose mesh is needle triangles; the wrap leaves it out "
                    "(widen it, or sew its neighbours to each other)",
                    name,
                )
            )
    return out


def _mean_width(poly: np.ndarray, area: float) -> tuple[float, float]:
    """A piece's mean width, twice its area over its perimeter (a strip's width), and its perimeter; cm."""
    perimeter = float(np.linalg.norm(poly - np.roll(poly, -1, axis=0), axis=1).sum())
    return 2.0 * area / perimeter, perimeter


def sliver_pieces(pattern: Pattern) -> dict[str, float]:
    """{name: mean width (cm)} of the pieces narrower on average than SLIVER_CM (`validate`'s "sliver" warning),
    in pattern order. Assumes a valid pattern (as `load_pattern` gives)."""
    out = {}
    for piece in pattern.pieces:
        poly, _ = piece.polygon_with_edges(tol_cm=INTERSECTION_TOL_CM)
        width, _ = _mean_width(poly, abs(geo.signed_area(poly)))
        if width < SLIVER_CM:
            out[piece.name] = width
    return out


def validate(pattern: Pattern) -> list[Issue]:
    """Check a pattern; returns every error and warning found (empty when all is well). Never raises."""
    issues: list[Issue] = []
    for name, count in (("pieces", len(pattern.pieces)), ("seams", len(pattern.seams))):
        try:
            limits.check(name, count, f"pattern has {count:,} {name}")
        except InputError as e:
            return [Issue("error", "over-limit", e.message)]  # checked first: the rest would take long
    if not pattern.pieces:
        issues.append(Issue("error", "no-pieces", "pattern has no pieces"))
    counts = Counter(p.name for p in pattern.pieces)
    for name, k in counts.items():
        if k > 1:
            issues.append(Issue("error", "duplicate-name", f"piece name {name!r} is used {k} times", name))
    for piece in pattern.pieces:
        issues.extend(_piece_issues(piece))

    by_name = {p.name: p for p in pattern.pieces}
    used: dict[EdgeRef, int] = {}
    for s, seam in enumerate(pattern.seams):
        ok = True
        for side in (seam.a, seam.b):
            piece = by_name.get(side.piece)
            if piece is None:
                issues.append(Issue("error", "unknown-piece", f"seam {s}: no piece named {side.piece!r}", seam=s))
                ok = False
            elif not 0 <= side.edge < piece.n_edges:
                issues.append(
                    Issue(
                        "error",
                        "unknown-edge",
                        f"seam {s}: piece {side.piece!r} has edges 0..{piece.n_edges - 1}, not {side.edge}",
                        side.piece,
                        s,
                    )
                )
                ok = False
        if not ok:
            continue
        if seam.a == seam.b:
            issues.append(Issue("error", "seam-self", f"seam {s}: joins edge {seam.a} to itself", seam.a.piece, s))
            continue
        for side in (seam.a, seam.b):
            if side in used:
                issues.append(
                    Issue(
                        "error",
                        "edge-in-two-seams",
                        f"seam {s}: edge {side} is already sewn by seam {used[side]} (split the edge instead)",
                        side.piece,
                        s,
                    )
                )
            used.setdefault(side, s)
        la, lb = pattern.edge_length(seam.a), pattern.edge_length(seam.b)
        longer = max(la, lb)
        if longer > 0 and abs(la - lb) > LENGTH_TOLERANCE * longer:
            issues.append(
                Issue(
                    "warning",
                    "length-mismatch",
                    f"seam {s}: {seam.a} is {la:.2f} cm but {seam.b} is {lb:.2f} cm "
                    f"({abs(la - lb) / longer:.1%} apart)",
                    seam.a.piece,
                    s,
                )
            )
    try:
        pattern_layers(pattern.meta, pattern.piece_names)
    except InputError as e:
        issues.append(Issue("error", "bad-layers", e.message))
    return issues


def check_pattern(pattern: Pattern, path: str | os.PathLike[str] | None = None) -> list[Issue]:
    """Raise InputError (naming `path`) for the first error of `validate`; return the warnings."""
    issues = validate(pattern)
    errors = [i for i in issues if i.severity == "error"]
    if errors:
        more = f" (and {len(errors) - 1} more problem{'s' * (len(errors) > 2)})" if len(errors) > 1 else ""
        raise InputError(errors[0].message + more, path)
    return [i for i in issues if i.severity == "warning"]
