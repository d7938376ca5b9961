"""Reading and writing patterns by file type: kitsuke JSON, GarmentCode JSON and SVG in; JSON, SVG and PNG out."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from .._files import read_json, write_bytes_atomic, write_text_atomic
from ..errors import InputError
from ._draw import TextureFill, pattern_sheet, sheet_to_png, sheet_to_svg
from ._garmentcode import garmentcode_from_dict, is_garmentcode
from ._kitsuke_json import FORMAT, pattern_from_dict, write_kitsuke
from ._svg_import import read_svg_with_issues
from ._types import Pattern
from ._validate import Issue, check_pattern

PATTERN_INPUTS = (".json", ".svg")
PATTERN_OUTPUTS = (".json", ".svg", ".png")


def load_pattern_with_issues(path: str | os.PathLike[str]) -> tuple[Pattern, list[Issue]]:
    """Like `load_pattern`, also returning the validation warnings (e.g. seam length mismatches)."""
    p = Path(path)
    suffix = p.suffix.lower()
    if suffix == ".svg":
        pattern, issues = read_svg_with_issues(p)
        pattern.source = str(p)
        return pattern, issues
    if suffix != ".json":
        raise InputError(f"unknown pattern file type {p.suffix or '(none)'!r} (use .json or .svg)", p)
    d = read_json(p, what="pattern file")
    try:
        if isinstance(d, dict) and d.get("format") == FORMAT:
            pattern = pattern_from_dict(d)
        elif is_garmentcode(d):
            stem = p.stem[: -len("_specification")] if p.stem.endswith("_specification") else p.stem
            pattern = garmentcode_from_dict(d, name=stem)
            pattern.meta["import"]["file"] = p.name
        elif isinstance(d, dict) and "format" in d:
            raise InputError(f"not a pattern file (format is {d['format']!r}, expected {FORMAT!r})")
        else:
            raise InputError(f"not a pattern file: neither kitsuke ({FORMAT!r}) nor a GarmentCode specification")
    except InputError as e:
        raise InputError(e.message, p) from None
    pattern.source = str(p)
    return pattern, check_pattern(pattern, p)


def load_pattern(path: str | os.PathLike[str]) -> Pattern:
    """Read a pattern file, whatever its kind: kitsuke JSON, GarmentCode JSON (told apart by content) or SVG.

    Fully validated: raises InputError naming the file for anything unusable (see `validate` for the list).
    """
    return load_pattern_with_issues(path)[0]


def _texture_fill(motif: str, repeat_cm: float, palette: str) -> TextureFill:
    from .texture import kimono_texture, texture_tile_size_cm

    def render(origin, size, px_per_cm):
        return kimono_texture(
            motif=motif, repeat_cm=repeat_cm, px_per_cm=px_per_cm, size_cm=size, origin_cm=origin, palette=palette
        )

    tile = kimono_texture(motif=motif, repeat_cm=repeat_cm, px_per_cm=60.0, palette=palette)
    return TextureFill(render, tile, texture_tile_size_cm(motif, repeat_cm))


def render_pattern_png(
    pattern: Pattern,
    *,
    max_px: int = 2400,
    texture: str | None = None,
    repeat_cm: float = 3.0,
    palette: str = "indigo",
    annotate: bool = True,
) -> np.ndarray:
    """The annotated flat-pattern picture as an (H, W, 3) uint8 image (longer side `max_px`).

    texture : None (paper-coloured pieces) or a motif ("asanoha", "seigaiha") drawn through pattern coordinates.
    """
    fill = None if texture is None else _texture_fill(texture, repeat_cm, palette)
    return sheet_to_png(pattern_sheet(pattern, texture=fill, annotate=annotate), max_px=max_px)


def render_pattern_svg(
    pattern: Pattern,
    *,
    texture: str | None = None,
    repeat_cm: float = 3.0,
    palette: str = "indigo",
    annotate: bool = True,
) -> str:
    """The annotated flat-pattern picture as an SVG document, true size (1 unit = 1 cm)."""
    fill = None if texture is None else _texture_fill(texture, repeat_cm, palette)
    return sheet_to_svg(pattern_sheet(pattern, texture=fill, annotate=annotate))


def save_pattern(pattern: Pattern, path: str | os.PathLike[str], **picture_options) -> Path:
    """Write a pattern by extension: .json (kitsuke JSON v1), .svg or .png (annotated picture). Atomic.

    `picture_options` go to `render_pattern_svg` / `render_pattern_png` (texture, repeat_cm, palette, annotate,
    and max_px for PNG).
    """
    p = Path(path)
    suffix = p.suffix.lower()
    if suffix == ".json":
        if picture_options:
            raise InputError("picture options apply to .svg and .png outputs only", p)
        write_kitsuke(pattern, p)
    elif suffix == ".svg":
        picture_options.pop("max_px", None)
        write_text_atomic(p, render_pattern_svg(pattern, **picture_options))
    elif suffix == ".png":
        import io

        from PIL import Image

        buf = io.BytesIO()
        Image.fromarray(render_pattern_png(pattern, **picture_options)).save(buf, format="PNG", optimize=True)
        write_bytes_atomic(p, buf.getvalue())
    else:
        raise InputError(f"unknown output type {p.suffix or '(none)'!r} (use .json, .svg or .png)", p)
    return p
