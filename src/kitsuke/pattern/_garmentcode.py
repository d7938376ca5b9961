"""Import of GarmentCode JSON pattern specifications (maria-korosteleva/GarmentCode, `*_specification.json`).

What the importer does, panel by panel:

1. Units: vertices (and circle radii) are scaled to cm with `properties.units_in_meter` (default 100); the panel's
   `translation` becomes metres (divided by `units_in_meter`), `rotation` stays XYZ Euler degrees (R = Rz Ry Rx,
   GarmentCode's `euler_xyz_to_R`).
2. Outline: the edges are chained by their endpoint indices into one closed loop, starting with edge 0 in its own
   direction; an edge listed backwards is traversed reversed (its curve reversed with it). So kitsuke edge k is
   GarmentCode edge k whenever the file's edges already form an ordered loop (they do in GarmentCode's own output);
   otherwise `meta["import"]["edge_map"]` records the renumbering.
3. Curves: relative control points carry over unchanged (same convention; `curvature_coords: "absolute"` files are
   converted). "quadratic" and "cubic" stay Béziers; "circle" ([radius, large_arc, right], SVG arc flags) becomes a
   kitsuke circle curve through the arc's middle (0.5, y), with y = +-sagitta / chord (negative when `right`).
4. Orientation: kitsuke outlines are counter-clockwise seen from the outer face (local +Z). GarmentCode panels are
   counter-clockwise seen from their outside, which for back panels is local -Z, so they come clockwise. Such a
   panel is mirrored (x -> -x: edge indices and directions unchanged, curve controls y -> -y) and its rotation
   gets a half turn about its local Y axis (R' = R @ Ry(180°)). Every point keeps its 3D position, and the outer
   face now is local +Z.
5. Stitches become seams, all reversed: after step 4 every piece faces outwards, and two outward pieces sewn into
   one consistently oriented garment meet with their edges running opposite ways (`decide_reversed`). The
   placement is not trusted to say otherwise (tiny stitches between far-apart panels tie; a hood is placed at
   right angles); where it clearly disagrees, `meta["import"]["notes"]` says so.
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any

import numpy as np

from .._files import read_json
from ..errors import InputError
from . import _geometry as geo
from ._types import Curve, EdgeRef, Pattern, Piece, Placement, Seam
from ._validate import Issue, check_pattern

#: Relative difference of the two end pairings below which a stitch direction counts as undecided.
AMBIGUOUS_PAIRING = 0.10


def is_garmentcode(d: Any) -> bool:
    """True when parsed JSON looks like a GarmentCode specification (`pattern.panels`)."""
    return isinstance(d, dict) and isinstance(d.get("pattern"), dict) and "panels" in d["pattern"]


def _num_array(v: Any, shape_tail: tuple[int, ...], ctx: str) -> np.ndarray:
    try:
        arr = np.array(v, dtype=np.float64)
    except (TypeError, ValueError):
        raise InputError(f"{ctx}: expected numbers") from None
    if arr.ndim != 1 + len(shape_tail) or arr.shape[1:] != shape_tail:
        raise InputError(f"{ctx}: expected shape (n, {', '.join(map(str, shape_tail))}), got {arr.shape}")
    if not np.isfinite(arr).all():
        raise InputError(f"{ctx}: NaN or infinity")
    return arr


def _chain(edges: list[tuple[int, int]], ctx: str) -> tuple[list[int], list[bool]]:
    """Order edges into one closed loop: (GarmentCode edge index per loop position, traversed reversed?)."""
    n = len(edges)
    order, flipped = [0], [False]
    used = {0}
    start, current = edges[0]
    while len(order) < n:
        nxt = next((k for k in range(n) if k not in used and edges[k][0] == current), None)
        rev = False
        if nxt is None:
            nxt = next((k for k in range(n) if k not in used and edges[k][1] == current), None)
            rev = True
        if nxt is None:
            raise InputError(f"{ctx}: edges do not form one closed loop (nothing continues from vertex {current})")
        used.add(nxt)
        order.append(nxt)
        flipped.append(rev)
        current = edges[nxt][0] if rev else edges[nxt][1]
    if current != start:
        raise InputError(f"{ctx}: edges do not close into a loop (ends at vertex {current}, began at {start})")
    starts = [edges[k][1] if r else edges[k][0] for k, r in zip(order, flipped, strict=True)]
    if len(set(starts)) != n:
        raise InputError(f"{ctx}: the edge loop visits a vertex twice")
    return order, flipped


def _curve(raw: Any, p0: np.ndarray, p1: np.ndarray, absolute: bool, scale: float, ctx: str) -> Curve | None:
    if raw is None:
        return None
    if isinstance(raw, list):  # legacy form: one quadratic control point
        raw = {"type": "quadratic", "params": [raw]}
    if not isinstance(raw, dict) or "type" not in raw or "params" not in raw:
        raise InputError(f"{ctx}: curvature must be {{type, params}}")
    kind, params = raw["type"], raw["params"]
    if kind == "circle":
        try:
            radius, large_arc, right = float(params[0]) * scale, bool(params[1]), bool(params[2])
        except (TypeError, ValueError, IndexError):
            raise InputError(f"{ctx}: circle params must be [radius, large_arc, right]") from None
        chord = float(np.linalg.norm(p1 - p0))
        if not math.isfinite(radius) or radius <= 0:
            raise InputError(f"{ctx}: circle radius must be a positive number")
        if not chord > 0.0:
            raise InputError(f"{ctx}: a circle edge of zero length (both ends are the same vertex)")
        half = 0.5 * chord
        # A radius a hair shorter than half the chord is a rounding artefact: take the half circle.
        rest = math.sqrt(max(radius * radius - half * half, 0.0))
        sagitta = radius + rest if large_arc else radius - rest
        y = sagitta / chord
        return Curve("circle", [[0.5, -y if right else y]])
    if kind not in ("quadratic", "cubic"):
        raise InputError(f"{ctx}: unsupported curvature type {kind!r} (quadratic, cubic and circle are read)")
    ctrl = _num_array(params, (2,), f"{ctx}: curvature params")
    if absolute:
        ctrl = geo.abs_to_rel(p0, p1, ctrl * scale)
    try:
        return Curve(kind, ctrl)
    except InputError as e:
        raise InputError(f"{ctx}: {e.message}") from None


def _panel(name: str, d: Any, scale: float, units_in_meter: float, absolute: bool, notes: list[str]):
    ctx = f"panel {name!r}"
    if not isinstance(d, dict):
        raise InputError(f"{ctx}: expected an object")
    for key in ("vertices", "edges"):
        if key not in d:
            raise InputError(f"{ctx}: missing field {key!r}")
    verts = _num_array(d["vertices"], (2,), f"{ctx}: vertices") * scale
    raw_edges = d["edges"]
    if not isinstance(raw_edges, list) or len(raw_edges) < 3:
        raise InputError(f"{ctx}: needs a list of at least 3 edges")
    ends: list[tuple[int, int]] = []
    for k, e in enumerate(raw_edges):
        ep = e.get("endpoints") if isinstance(e, dict) else None
        if (
            not isinstance(ep, list)
            or len(ep) != 2
            or not all(isinstance(i, int) and not isinstance(i, bool) and 0 <= i < len(verts) for i in ep)
        ):
            raise InputError(f"{ctx}: edge {k}: endpoints must be two vertex indices 0..{len(verts) - 1}")
        ends.append((ep[0], ep[1]))
    order, rev = _chain(ends, ctx)
    outline = np.array([verts[ends[g][1] if r else ends[g][0]] for g, r in zip(order, rev, strict=True)])
    curves: dict[int, Curve] = {}
    for k, (g, r) in enumerate(zip(order, rev, strict=True)):
        p0, p1 = verts[ends[g][0]], verts[ends[g][1]]
        c = _curve(raw_edges[g].get("curvature"), p0, p1, absolute, scale, f"{ctx}: edge {g}")
        if c is not None:
            curves[k] = c.reversed() if r else c
    t = _num_array([d.get("translation", [0, 0, 0])], (3,), f"{ctx}: translation")[0] / units_in_meter
    rot = _num_array([d.get("rotation", [0, 0, 0])], (3,), f"{ctx}: rotation")[0]
    placement = Placement(t, rot)
    # The true outline decides, arcs included: a circle skirt's corners all lie on one line (zero polygon area),
    # and its arcs alone say which way it runs.
    mirrored = Piece(name, outline, curves).signed_area < 0
    if mirrored:
        outline = outline * np.array([-1.0, 1.0])
        curves = {k: c.mirrored() for k, c in curves.items()}
        placement = Placement(t, geo.matrix_to_euler_xyz(placement.matrix @ geo.euler_xyz_matrix([0, 180, 0])))
        notes.append(f"{name}: clockwise in GarmentCode; mirrored in x and turned 180° about its local Y")
    edge_map = {g: k for k, g in enumerate(order)}
    return Piece(name, outline, curves, False, placement), edge_map, mirrored


def _stitch_side(s: Any, ctx: str) -> tuple[str, int]:
    if not isinstance(s, dict) or "panel" not in s or "edge" not in s:
        raise InputError(f"{ctx}: each side needs 'panel' and 'edge'")
    if not isinstance(s["panel"], str) or isinstance(s["edge"], bool) or not isinstance(s["edge"], int):
        raise InputError(f"{ctx}: panel must be a name and edge an integer")
    return s["panel"], s["edge"]


def decide_reversed(pa: Piece, ea: int, pb: Piece, eb: int) -> tuple[bool, str]:
    """Which ends of two stitched edges meet: (reversed, how it was decided).

    The orientation decides: every imported piece runs counter-clockwise seen from its outer face, and two such
    pieces sewn into one consistently oriented garment meet with their edges running opposite ways, so a stitch is
    reversed. The placement only confirms it ("distance": the crossed end pairing is 10 % or more closer in 3D;
    "direction": the placed edges run opposite ways, cosine <= -0.5) or is silent ("orientation"). A placement that
    clearly says otherwise ("placement disagrees") is overruled: placement distances mislead for tiny edges
    (0.1-1.5 cm stitches between a bodice and a skirt placed 0.5 m apart, whose pairings tie at 100.84 vs 100.87
    cm) and for pieces placed at right angles (a hood), while a stitch that is not reversed would turn one piece
    inside out against the other.
    """
    a = pa.placement.apply(np.array(pa.edge_endpoints(ea))) if pa.placement is not None else None
    b = pb.placement.apply(np.array(pb.edge_endpoints(eb))) if pb.placement is not None else None
    if a is None or b is None:
        return True, "orientation"
    same = float(np.linalg.norm(a[0] - b[0]) + np.linalg.norm(a[1] - b[1]))
    crossed = float(np.linalg.norm(a[0] - b[1]) + np.linalg.norm(a[1] - b[0]))
    if abs(same - crossed) >= AMBIGUOUS_PAIRING * max(same, crossed):
        return True, "distance" if crossed < same else "placement disagrees"
    da, db = a[1] - a[0], b[1] - b[0]
    cos = float(da @ db) / max(float(np.linalg.norm(da) * np.linalg.norm(db)), 1e-300)
    if abs(cos) >= 0.5:
        return True, "direction" if cos < 0 else "placement disagrees"
    return True, "orientation"


def garmentcode_from_dict(d: Any, *, name: str = "garment") -> Pattern:
    """Convert a parsed GarmentCode specification into a Pattern (InputError without a file name on bad data)."""
    if not is_garmentcode(d):
        raise InputError("not a GarmentCode specification (no pattern.panels)")
    props = d.get("properties", {}) if isinstance(d.get("properties", {}), dict) else {}
    units_in_meter = props.get("units_in_meter", 100)
    if isinstance(units_in_meter, bool) or not isinstance(units_in_meter, int | float) or not units_in_meter > 0:
        raise InputError("properties.units_in_meter must be a positive number")
    scale = 100.0 / float(units_in_meter)
    absolute = props.get("curvature_coords", "relative") == "absolute"
    panels = d["pattern"]["panels"]
    if not isinstance(panels, dict) or not panels:
        raise InputError("pattern.panels must be a non-empty object")
    order = d["pattern"].get("panel_order")
    names = [n for n in order if isinstance(n, str) and n in panels] if isinstance(order, list) else []
    names += [n for n in panels if n not in names]
    notes: list[str] = []
    pieces, edge_maps = [], {}
    flipped_panels = set()
    for pname in names:
        piece, emap, mirrored = _panel(pname, panels[pname], scale, float(units_in_meter), absolute, notes)
        if mirrored:
            flipped_panels.add(pname)
        pieces.append(piece)
        edge_maps[pname] = emap
    by_name = {p.name: p for p in pieces}
    seams = []
    stitches = d["pattern"].get("stitches", [])
    if not isinstance(stitches, list):
        raise InputError("pattern.stitches must be a list")
    for i, st in enumerate(stitches):
        sides = [s for s in st if isinstance(s, dict) and "panel" in s] if isinstance(st, list) else []
        if len(sides) != 2:
            raise InputError(f"stitch {i}: expected two sides [{{panel, edge}}, {{panel, edge}}]")
        refs = []
        for side in sides:
            pname, g = _stitch_side(side, f"stitch {i}")
            if pname not in by_name:
                raise InputError(f"stitch {i}: no panel named {pname!r}")
            if g not in edge_maps[pname]:
                raise InputError(f"stitch {i}: panel {pname!r} has edges 0..{len(edge_maps[pname]) - 1}, not {g}")
            refs.append(EdgeRef(pname, edge_maps[pname][g]))
        rev, how = decide_reversed(by_name[refs[0].piece], refs[0].edge, by_name[refs[1].piece], refs[1].edge)
        if how == "placement disagrees":
            notes.append(f"stitch {i}: the placement pairs its ends the other way; reversed (both face outwards)")
        seams.append(Seam(refs[0], refs[1], rev))
    meta: dict[str, Any] = {"import": {"from": "garmentcode", "notes": notes}}
    renumbered = {
        p: {str(g): k for g, k in m.items()} for p, m in edge_maps.items() if any(g != k for g, k in m.items())
    }
    if renumbered:
        meta["import"]["edge_map"] = renumbered
    return Pattern(name, pieces, seams, meta, file_mirrored=frozenset(flipped_panels))


def _name_from_path(path: Path) -> str:
    stem = path.stem
    return stem[: -len("_specification")] if stem.endswith("_specification") else stem


def read_garmentcode_with_issues(path: str | os.PathLike[str]) -> tuple[Pattern, list[Issue]]:
    p = Path(path)
    d = read_json(p, what="GarmentCode specification")
    try:
        pattern = garmentcode_from_dict(d, name=_name_from_path(p))
    except InputError as e:
        raise InputError(e.message, p) from None
    pattern.meta["import"]["file"] = p.name
    return pattern, check_pattern(pattern, p)


def read_garmentcode(path: str | os.PathLike[str]) -> Pattern:
    """Read a GarmentCode JSON specification as a Pattern; InputError naming the file on any problem."""
    return read_garmentcode_with_issues(path)[0]
