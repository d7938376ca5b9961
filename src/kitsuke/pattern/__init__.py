"""Sewing patterns: pieces, seams, file formats, the kimono generator, textile textures and triangulation.

Data model (see `Piece` for the conventions): a `Pattern` holds `Piece`s (outline in cm, counter-clockwise seen
from the outer face, optional `Curve` per edge, optional `Placement` hint) and `Seam`s joining two whole edges
(`EdgeRef`). Everything reads and writes through a few functions:

- `load_pattern(path)`: kitsuke JSON, GarmentCode JSON (told apart by content) or SVG, fully validated.
- `save_pattern(pattern, path)`: .json (kitsuke v1), .svg or .png (annotated picture; optional texture).
- `validate(pattern) -> list[Issue]`: errors and warnings (e.g. seam length mismatch above 1 %).
- `make_kimono(KimonoSize(...))`: the parametric kimono; `default_kimono()`: the one the demo dresses (cut to the
  default body, `fitted_size`); `kimono_texture(...)`: asanoha / seigaiha.
- `mesh_pattern(pattern, edge_length=1.5)` -> `PatternMesh` (seam-matched Triangle meshes), `write_pattern_obj`.
"""

from ._draw import pattern_sheet, sheet_to_png, sheet_to_svg
from ._garmentcode import decide_reversed, garmentcode_from_dict, read_garmentcode
from ._io import load_pattern, load_pattern_with_issues, render_pattern_png, render_pattern_svg, save_pattern
from ._kitsuke_json import pattern_from_dict, pattern_to_dict, read_kitsuke, write_kitsuke
from ._layers import LayerRegion, face_layers, pattern_layers
from ._mesh import PatternMesh, mesh_pattern, mesh_quality, obj_text, write_pattern_obj
from ._svg_import import read_svg
from ._types import Curve, CurveType, EdgeRef, Fold, Pattern, Piece, Placement, Seam
from ._validate import Issue, check_pattern, sliver_pieces, validate
from .kimono import KimonoSize, default_kimono, fitted_size, make_kimono
from .texture import MOTIFS, PALETTES, kimono_texture, texture_tile_size_cm, texture_uv

__all__ = [
    "MOTIFS",
    "PALETTES",
    "Curve",
    "CurveType",
    "EdgeRef",
    "Fold",
    "Issue",
    "KimonoSize",
    "LayerRegion",
    "Pattern",
    "PatternMesh",
    "Piece",
    "Placement",
    "Seam",
    "check_pattern",
    "decide_reversed",
    "face_layers",
    "garmentcode_from_dict",
    "kimono_texture",
    "load_pattern",
    "load_pattern_with_issues",
    "make_kimono",
    "default_kimono",
    "fitted_size",
    "mesh_pattern",
    "mesh_quality",
    "obj_text",
    "pattern_from_dict",
    "pattern_layers",
    "pattern_sheet",
    "pattern_to_dict",
    "read_garmentcode",
    "read_kitsuke",
    "read_svg",
    "render_pattern_png",
    "render_pattern_svg",
    "save_pattern",
    "sheet_to_png",
    "sheet_to_svg",
    "texture_tile_size_cm",
    "texture_uv",
    "sliver_pieces",
    "validate",
    "write_kitsuke",
    "write_pattern_obj",
]
