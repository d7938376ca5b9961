"""kitsuke pattern JSON v1 (SPEC §3.1): read, write, and convert to and from plain dicts.

File layout::

    {"format": "kitsuke.pattern", "version": 1, "units": "cm", "name": "kimono",
     "pieces": [{"name": "...", "outline": [[x, y], ...],
                 "curves": {"2": {"type": "quadratic", "control": [[0.5, 0.1]]}},     # optional
                 "flipped": false,                                                     # optional
                 "placement": {"translation": [x, y, z], "rotation_deg": [rx, ry, rz],  # optional, metres
                               "fold": {"y_cm": 158, "diameter_cm": 26}}}],              # optional
     "seams": [{"a": {"piece": "...", "edge": 0}, "b": {"piece": "...", "edge": 4}, "reversed": true}],
     "meta": {...}}                                                                    # optional, free-form
                                          # meta "layers": which pieces lie over which when worn (see `_layers`)

`units` may be "cm" (the default and what is written), "mm", "m" or "in": other units are scaled to cm on reading.
`reversed` defaults to true. Curve types: quadratic, cubic (Bézier) and circle (an arc through the relative point
(0.5, y)); `fold` is kitsuke's extension for pieces that run over a shoulder (see `Fold`). Unknown keys are ignored.
"""

from __future__ import annotations

import math
import os
from typing import Any

from .._files import read_json, write_json_atomic
from ..errors import InputError
from ._types import Curve, EdgeRef, Fold, Pattern, Piece, Placement, Seam
from ._validate import Issue, check_pattern

FORMAT = "kitsuke.pattern"
VERSION = 1
UNIT_TO_CM = {"cm": 1.0, "mm": 0.1, "m": 100.0, "in": 2.54}


def _where(ctx: str, msg: str) -> str:
    return f"{ctx}: {msg}" if ctx else msg


def _number(v: Any, ctx: str) -> float:
    if isinstance(v, bool) or not isinstance(v, int | float):
        raise InputError(_where(ctx, f"expected a number, got {json_type(v)}"))
    if not math.isfinite(v):
        raise InputError(_where(ctx, "NaN or infinity is not allowed"))
    return float(v)


def _points(v: Any, dim: int, ctx: str) -> list[list[float]]:
    if not isinstance(v, list):
        raise InputError(_where(ctx, f"expected a list of [{', '.join('xyz'[:dim])}] points, got {json_type(v)}"))
    out = []
    for k, p in enumerate(v):
        if not isinstance(p, list) or len(p) != dim:
            raise InputError(_where(f"{ctx}[{k}]", f"expected {dim} numbers"))
        out.append([_number(x, f"{ctx}[{k}]") for x in p])
    return out


def _vector(v: Any, ctx: str) -> list[float]:
    if not isinstance(v, list) or len(v) != 3:
        raise InputError(_where(ctx, "expected a list of 3 numbers"))
    return [_number(x, ctx) for x in v]


def json_type(v: Any) -> str:
    return {dict: "an object", list: "a list", str: "a string", bool: "true/false", type(None): "null"}.get(
        type(v), "a number"
    )


def _require(d: dict, key: str, ctx: str) -> Any:
    if key not in d:
        raise InputError(_where(ctx, f"missing field {key!r}"))
    return d[key]


def _object(v: Any, ctx: str) -> dict:
    if not isinstance(v, dict):
        raise InputError(_where(ctx, f"expected an object, got {json_type(v)}"))
    return v


def _piece_from_dict(d: Any, ctx: str, scale: float) -> Piece:
    d = _object(d, ctx)
    name = _require(d, "name", ctx)
    if not isinstance(name, str) or not name.strip():
        raise InputError(_where(ctx, "name must be a non-empty string"))
    ctx = f"piece {name!r}"
    outline = [[x * scale, y * scale] for x, y in _points(_require(d, "outline", ctx), 2, f"{ctx}: outline")]
    curves = {}
    for key, c in _object(d.get("curves", {}), f"{ctx}: curves").items():
        try:
            edge = int(key)
        except ValueError:
            raise InputError(_where(ctx, f"curves key {key!r} is not an edge index")) from None
        c = _object(c, f"{ctx}: curve {key}")
        ctype = _require(c, "type", f"{ctx}: curve {key}")
        control = _points(_require(c, "control", f"{ctx}: curve {key}"), 2, f"{ctx}: curve {key}: control")
        try:
            curves[edge] = Curve(ctype, control)
        except InputError as e:
            raise InputError(f"{ctx}: curve {key}: {e.message}") from None
    flipped = d.get("flipped", False)
    if not isinstance(flipped, bool):
        raise InputError(_where(ctx, "flipped must be true or false"))
    placement = None
    if d.get("placement") is not None:
        pd = _object(d["placement"], f"{ctx}: placement")
        t = _vector(pd.get("translation", [0, 0, 0]), f"{ctx}: placement.translation")
        r = _vector(pd.get("rotation_deg", [0, 0, 0]), f"{ctx}: placement.rotation_deg")
        fold = None
        if pd.get("fold") is not None:
            fd = _object(pd["fold"], f"{ctx}: placement.fold")
            y = _number(_require(fd, "y_cm", f"{ctx}: placement.fold"), f"{ctx}: placement.fold.y_cm")
            dia = _number(_require(fd, "diameter_cm", f"{ctx}: placement.fold"), f"{ctx}: placement.fold.diameter_cm")
            try:
                fold = Fold(y * scale, dia * scale)
            except InputError as e:
                raise InputError(f"{ctx}: placement.fold: {e.message}") from None
        placement = Placement(t, r, fold)
    try:
        return Piece(name, outline, curves, flipped, placement)
    except InputError as e:
        raise InputError(e.message if e.message.startswith("piece ") else f"{ctx}: {e.message}") from None


def _edge_ref(d: Any, ctx: str) -> EdgeRef:
    d = _object(d, ctx)
    piece = _require(d, "piece", ctx)
    edge = _require(d, "edge", ctx)
    if not isinstance(piece, str):
        raise InputError(_where(ctx, "piece must be a piece name (a string)"))
    if isinstance(edge, bool) or not isinstance(edge, int):
        raise InputError(_where(ctx, f"edge must be an integer edge index, got {edge!r}"))
    return EdgeRef(piece, edge)


def pattern_from_dict(d: Any) -> Pattern:
    """Build a Pattern from the parsed JSON of a kitsuke pattern file; InputError (no file name) when malformed.

    Checks the structure only; `validate` / `check_pattern` check the geometry and the seams.
    """
    d = _object(d, "")
    fmt = d.get("format")
    if fmt != FORMAT:
        raise InputError(f"not a kitsuke pattern (format is {fmt!r}, expected {FORMAT!r})")
    version = d.get("version")
    if version != VERSION:
        raise InputError(f"unsupported kitsuke.pattern version {version!r} (this kitsuke reads version {VERSION})")
    units = d.get("units", "cm")
    if not isinstance(units, str) or units not in UNIT_TO_CM:
        raise InputError(f"unknown units {units!r} (use cm, mm, m or in)")
    scale = UNIT_TO_CM[units]
    name = d.get("name", "pattern")
    if not isinstance(name, str):
        raise InputError("name must be a string")
    pieces_raw = _require(d, "pieces", "")
    if not isinstance(pieces_raw, list):
        raise InputError(f"pieces must be a list, got {json_type(pieces_raw)}")
    pieces = [_piece_from_dict(p, f"pieces[{i}]", scale) for i, p in enumerate(pieces_raw)]
    seams_raw = d.get("seams", [])
    if not isinstance(seams_raw, list):
        raise InputError(f"seams must be a list, got {json_type(seams_raw)}")
    seams = []
    for i, s in enumerate(seams_raw):
        s = _object(s, f"seams[{i}]")
        rev = s.get("reversed", True)
        if not isinstance(rev, bool):
            raise InputError(f"seams[{i}]: reversed must be true or false")
        seams.append(
            Seam(
                _edge_ref(_require(s, "a", f"seams[{i}]"), f"seams[{i}].a"),
                _edge_ref(_require(s, "b", f"seams[{i}]"), f"seams[{i}].b"),
                rev,
            )
        )
    meta = d.get("meta", {})
    if not isinstance(meta, dict):
        raise InputError(f"meta must be an object, got {json_type(meta)}")
    return Pattern(name, pieces, seams, meta)


def _floats(a) -> list:
    return [[float(v) for v in row] for row in a]


def pattern_to_dict(pattern: Pattern) -> dict:
    """The kitsuke JSON v1 form of a pattern (plain dicts and lists, units cm)."""
    pieces = []
    for p in pattern.pieces:
        d: dict[str, Any] = {"name": p.name, "outline": _floats(p.outline)}
        if p.curves:
            d["curves"] = {str(i): {"type": c.type, "control": _floats(c.control)} for i, c in p.curves.items()}
        d["flipped"] = p.flipped
        if p.placement is not None:
            pl: dict[str, Any] = {
                "translation": [float(v) for v in p.placement.translation],
                "rotation_deg": [float(v) for v in p.placement.rotation_deg],
            }
            if p.placement.fold is not None:
                pl["fold"] = {"y_cm": p.placement.fold.y_cm, "diameter_cm": p.placement.fold.diameter_cm}
            d["placement"] = pl
        pieces.append(d)
    seams = [
        {
            "a": {"piece": s.a.piece, "edge": int(s.a.edge)},
            "b": {"piece": s.b.piece, "edge": int(s.b.edge)},
            "reversed": bool(s.reversed),
        }
        for s in pattern.seams
    ]
    out: dict[str, Any] = {"format": FORMAT, "version": VERSION, "units": "cm", "name": pattern.name}
    out["pieces"] = pieces
    out["seams"] = seams
    if pattern.meta:
        out["meta"] = pattern.meta
    return out


def read_kitsuke(path: str | os.PathLike[str]) -> Pattern:
    """Read and fully validate a kitsuke pattern file (InputError naming the file on any problem)."""
    return read_kitsuke_with_issues(path)[0]


def read_kitsuke_with_issues(path: str | os.PathLike[str]) -> tuple[Pattern, list[Issue]]:
    d = read_json(path, what="pattern file")
    try:
        pattern = pattern_from_dict(d)
    except InputError as e:
        raise InputError(e.message, path) from None
    return pattern, check_pattern(pattern, path)


def write_kitsuke(pattern: Pattern, path: str | os.PathLike[str]) -> None:
    """Write a pattern as kitsuke JSON v1 (atomically)."""
    write_json_atomic(path, pattern_to_dict(pattern))
