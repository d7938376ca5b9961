"""Import of closed SVG paths as pattern pieces (FreeSewing exports and generic drawings).

- Units: svgelements resolves the document's width/height/viewBox and every transform to CSS pixels (96 per inch),
  which we turn into cm. A FreeSewing file (width="1123.47mm" with a matching viewBox) thus comes out in true size.
  An SVG without physical units is read at 96 px per inch, like browsers and Inkscape do.
- Which shapes are pieces: in a FreeSewing file (one that has paths of class "fabric", "lining", "interfacing",
  "canvas" or "various"), exactly those paths, except the seam-allowance outline (class "... sa"); notes, marks,
  help lines, the scale box, logos and everything under <defs> (markers, snippets) are not pieces. In any other SVG,
  every closed shape (path, rect, polygon, circle, ellipse) outside <defs> is a piece; each closed sub-path of a path
  is its own piece (holes are not supported). Open sub-paths are skipped.
- Names: FreeSewing part ids (group "fs-stack-teagan.front-part-teagan.front" -> "front"); otherwise the element's
  id, else piece_N. Repeated names get _2, _3.
- Geometry: every path segment becomes one edge. Lines stay straight; quadratic and cubic Béziers keep their curve
  as relative control points; elliptical arcs are converted to cubic Béziers (one edge per quarter turn or less).
  Zero-length segments (a closing "z" after a line back to the start) are dropped.
- Axes: SVG's y points down; kitsuke's y points up, so y is negated, and outlines are then made counter-clockwise
  (the point order reversed where needed, curves reversed with their edges). Each piece is moved so that its
  bounding box starts at (0, 0).
- No seams (SVG carries no stitching) and no placement.
"""

from __future__ import annotations

import os
import re
from pathlib import Path
from typing import Any

import numpy as np

from .. import limits
from .._files import require_file
from ..errors import InputError
from . import _geometry as geo
from ._types import Curve, Pattern, Piece
from ._validate import Issue, check_pattern

#: FreeSewing's material classes: paths of these classes are piece outlines.
MATERIAL_CLASSES = {"fabric", "lining", "interfacing", "canvas", "various"}
#: CSS px per cm (svgelements resolves everything to px at 96 per inch).
PX_PER_CM = 96.0 / 2.54


def _tokens(shape: Any) -> set[str]:
    cls = shape.values.get("class") if hasattr(shape, "values") else None
    return set(str(cls).split()) if cls else set()


def _walk(group: Any, ancestors: tuple[str, ...], out: list) -> None:
    import svgelements as se

    for child in group:
        if isinstance(child, se.Group):
            _walk(child, (*ancestors, str(child.id)) if child.id else ancestors, out)
        elif isinstance(child, se.Shape) and not isinstance(child, se.SimpleLine):
            out.append((child, ancestors))


def _freesewing_part(ancestors: tuple[str, ...]) -> str | None:
    for gid in reversed(ancestors):
        m = re.search(r"-part-[^.]+\.(.+)$", gid) or re.match(r"fs-stack-[^.]+\.(.+)$", gid)
        if m:
            return m.group(1)
    return None


def _subpaths(shape: Any) -> list[list]:
    """Closed sub-paths of a shape as lists of segments (svgelements objects), in px."""
    import svgelements as se

    path = shape if isinstance(shape, se.Path) else se.Path(shape)
    out = []
    for sub in path.as_subpaths():
        segs = [s for s in sub if not isinstance(s, se.Move)]
        if not segs:
            continue
        start = np.array([segs[0].start.x, segs[0].start.y])
        end = np.array([segs[-1].end.x, segs[-1].end.y])
        closed = isinstance(segs[-1], se.Close) or float(np.linalg.norm(end - start)) < 1e-6
        if closed:
            out.append(segs)
    return out


def _edges(segments: list) -> list[tuple[np.ndarray, np.ndarray, str | None, np.ndarray | None]]:
    """Segments (px, y down) -> edges (cm, y up): (start, end, curve type or None, absolute controls or None)."""
    import svgelements as se

    def cm(p) -> np.ndarray:
        return np.array([p.x, -p.y], dtype=np.float64) / PX_PER_CM

    expanded = []
    for s in segments:
        if isinstance(s, se.Arc):
            expanded.extend(s.as_cubic_curves())
        else:
            expanded.append(s)
    edges = []
    for s in expanded:
        p0, p1 = cm(s.start), cm(s.end)
        chord = float(np.linalg.norm(p1 - p0))
        if chord < 1e-7:
            continue
        if isinstance(s, se.CubicBezier):
            kind, ctrl = "cubic", np.stack([cm(s.control1), cm(s.control2)])
        elif isinstance(s, se.QuadraticBezier):
            kind, ctrl = "quadratic", cm(s.control)[None, :]
        else:
            kind, ctrl = None, None
        if ctrl is not None:
            rel = geo.abs_to_rel(p0, p1, ctrl)
            if np.abs(rel[:, 1]).max() < 1e-9 and rel[:, 0].min() >= 0 and rel[:, 0].max() <= 1:
                kind, ctrl = None, None  # a straight line written as a curve
        edges.append((p0, p1, kind, ctrl))
    # Make the loop exactly closed: the last edge ends where the first starts.
    if edges:
        p0, _, kind, ctrl = edges[-1]
        edges[-1] = (p0, edges[0][0], kind, ctrl)
    return edges


def _split_half(edge):
    """Split a Bézier edge at t = 1/2 (de Casteljau) into two edges of the same curve."""
    p0, p1, kind, c = edge
    if kind == "quadratic":
        a, b = 0.5 * (p0 + c[0]), 0.5 * (c[0] + p1)
        m = 0.5 * (a + b)
        return [(p0, m, kind, a[None]), (m, p1, kind, b[None])]
    a, bc, d = 0.5 * (p0 + c[0]), 0.5 * (c[0] + c[1]), 0.5 * (c[1] + p1)
    ab, cd = 0.5 * (a + bc), 0.5 * (bc + d)
    m = 0.5 * (ab + cd)
    return [(p0, m, kind, np.stack([a, ab])), (m, p1, kind, np.stack([cd, d]))]


def _check_edges(name: str, edges: list) -> None:
    """Refuse, before any curve is sampled, numbers that are not finite (a transform can overflow them) and an edge
    past the size limit (a curve 10^9 cm long would be sampled into billions of points). Segments of zero length
    were dropped already (`_edges`)."""
    for i, (p0, p1, kind, c) in enumerate(edges):
        pts = np.vstack([p0, p1] if c is None else [p0, p1, c])
        if not np.isfinite(pts).all():
            raise InputError(f"shape {name!r}: segment {i} has coordinates that are not finite numbers")
        rel = None if c is None else geo.abs_to_rel(p0, p1, c)
        length = geo.curve_length_bound(p0, p1, kind, rel) / 100.0
        limits.check("edge_m", length, f"shape {name!r}: segment {i} is {length:,.4g} m long")


def _piece(name: str, edges: list) -> Piece:
    _check_edges(name, edges)
    # A piece needs three corners: a lens or a D shape drawn with two segments gets its curves split in half.
    while len(edges) < 3:
        k = next(i for i, e in enumerate(edges) if e[2] in ("quadratic", "cubic"))
        edges = edges[:k] + _split_half(edges[k]) + edges[k + 1 :]
    outline = np.array([e[0] for e in edges])
    poly = np.concatenate(
        [
            geo.sample_curve(p0, p1, k, None if c is None else geo.abs_to_rel(p0, p1, c), 0.01)[:-1]
            for p0, p1, k, c in edges
        ]
    )
    if geo.signed_area(poly) < 0:  # clockwise after the y flip: walk the loop the other way
        edges = [(p1, p0, k, None if c is None else c[::-1]) for p0, p1, k, c in reversed(edges)]
        outline = np.array([e[0] for e in edges])
        poly = poly[::-1]
    origin = poly.min(axis=0)
    curves = {i: Curve(k, geo.abs_to_rel(p0, p1, c)) for i, (p0, p1, k, c) in enumerate(edges) if k is not None}
    return Piece(name, outline - origin, curves)


#: Elements an SVG may expand to through <use> (a pattern has a few hundred; a <use> chain can multiply them).
MAX_EXPANDED_ELEMENTS = 100_000


def _check_structure(path: Path) -> None:
    """Refuse, before svgelements expands them, <use> references that form a cycle (an element used inside
    itself: svgelements would expand it forever) or that multiply the document past MAX_EXPANDED_ELEMENTS."""
    import xml.etree.ElementTree as ET

    try:
        root = ET.parse(path).getroot()
    except (ET.ParseError, LookupError, ValueError) as e:  # LookupError: an unknown encoding in the XML header
        raise InputError(f"not a readable SVG file ({type(e).__name__}: {e})", path) from None
    except RecursionError:
        raise InputError("not a readable SVG file (nested too deeply)", path) from None
    ids = {e.get("id"): e for e in root.iter() if e.get("id")}
    counts: dict[int, int] = {}

    def expanded(element, active: set[int]) -> int:
        key = id(element)
        if key in counts:
            return counts[key]
        if key in active:
            raise InputError(f"<use> elements form a cycle through #{element.get('id')}", path)
        active.add(key)
        n = 1
        for child in element:
            n += expanded(child, active)
        if element.tag.rsplit("}", 1)[-1] == "use":
            href = element.get("{http://www.w3.org/1999/xlink}href") or element.get("href") or ""
            target = ids.get(href[1:]) if href.startswith("#") else None
            if target is not None:
                n += expanded(target, active)
        active.discard(key)
        if n > MAX_EXPANDED_ELEMENTS:
            raise InputError(f"<use> elements expand the document past {MAX_EXPANDED_ELEMENTS:,} elements", path)
        counts[key] = n
        return n

    try:
        expanded(root, set())
    except RecursionError:
        raise InputError("not a readable SVG file (nested too deeply)", path) from None


def svg_to_pattern(path: str | os.PathLike[str]) -> Pattern:
    """Parse an SVG file into a Pattern without validating it (see `read_svg`)."""
    import svgelements as se

    p = require_file(path, what="SVG file")
    _check_structure(p)
    try:
        svg = se.SVG.parse(str(p), reify=True, ppi=96.0)
    except Exception as e:  # noqa: BLE001 - the XML parser raises several types; all mean "not a readable SVG"
        raise InputError(f"not a readable SVG file ({type(e).__name__}: {e})", p) from None
    if not isinstance(svg, se.Group):
        raise InputError("not an SVG document (no <svg> root element)", p)
    shapes: list = []
    _walk(svg, (), shapes)
    freesewing = any(_tokens(s) & MATERIAL_CLASSES for s, _ in shapes)
    pieces: list[Piece] = []
    used: dict[str, int] = {}
    notes: list[str] = []
    for shape, ancestors in shapes:
        tokens = _tokens(shape)
        if freesewing and (not tokens & MATERIAL_CLASSES or "sa" in tokens):
            continue
        if not freesewing and "hidden" in tokens:
            continue
        base = (_freesewing_part(ancestors) if freesewing else None) or shape.id or f"piece_{len(pieces) + 1}"
        subs = _subpaths(shape)
        if freesewing and not subs:
            notes.append(f"{base}: outline is not closed; skipped")
        for segs in subs:
            edges = _edges(segs)
            if len(edges) < 2:
                continue
            if len(edges) == 2 and edges[0][2] is None and edges[1][2] is None:
                continue  # a degenerate back-and-forth line
            used[base] = used.get(base, 0) + 1
            name = base if used[base] == 1 else f"{base}_{used[base]}"
            try:
                pieces.append(_piece(name, edges))
            except InputError as e:
                raise InputError(e.message, p) from None
    if not pieces:
        raise InputError("no closed shapes found (nothing to make pieces of)", p)
    units = str(svg.values.get("width", "") or "")
    unit = re.sub(r"[\d.+\-eE\s]", "", units) or "px (none given: 96 per inch)"
    meta = {
        "import": {"from": "freesewing svg" if freesewing else "svg", "file": p.name, "units": unit, "notes": notes}
    }
    return Pattern(p.stem, pieces, [], meta)


def read_svg_with_issues(path: str | os.PathLike[str]) -> tuple[Pattern, list[Issue]]:
    pattern = svg_to_pattern(path)
    return pattern, check_pattern(pattern, Path(path))


def read_svg(path: str | os.PathLike[str]) -> Pattern:
    """Read the closed shapes of an SVG file as pattern pieces (cm, y up, counter-clockwise); InputError naming the
    file when it is not an SVG, holds no closed shape, or a shape is unusable (e.g. self-intersecting)."""
    return read_svg_with_issues(path)[0]
