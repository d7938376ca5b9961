"""Sketch-based dressing (SPEC §4): corresponding strokes on the pattern and the body, and the wrap.

- `wrap(body, pattern_or_mesh, strokes)` -> `DressedGarment`: strokes' triangles placed on the body, the rest grown
  from the placed cloth, seams shut, a gravity settle; with a quality report.

- `rewrap(body, dressed, strokes, pins=...)` (`kitsuke.dressing.rewrap`): strokes with "target": "garment" move
  part of a dressed garment; pins hold the rest.
- `DragSession(body, dressed)`: grab / move_to / move_by / release / pin / unpin, the garment following along the
  body surface; `read_drags` / `apply_drags`: replay a kitsuke drags v1 file (SPEC §3.5).
- `dress_default_kimono()` (`kitsuke.dressing.kimono`): the demo's kimono on the default body, obi band held.

- `read_strokes(path)` / `write_strokes(strokes, path)`: kitsuke strokes v1 JSON (SPEC §3.2).
- `check_strokes(strokes, pattern, pattern_mesh=...)`: the pattern side (pieces, points on them, triangles
  crossed).
- `resolve_strokes(strokes, pattern, surface)`: body strokes projected (drawn points) or cast (laser rays)
  onto the body or garment surface, each point with its face and barycentric coordinates.
- Helpers for the wrap: `triangles_crossed`, `arc_length`, `arc_parameters`, `resample_polyline`,
  `resample_on_surface`, `stroke_coordinates`.
- `packaged_strokes_path()` / `load_packaged_strokes()`: shipped strokes (the kimono on the default body).
"""

from importlib import resources
from pathlib import Path

from ._polish_step import PolishSettings
from ._polyline import (
    arc_length,
    arc_parameters,
    densify_polyline,
    interpolate_polyline,
    resample_on_surface,
    resample_polyline,
    stroke_coordinates,
    surface_length,
    surface_polyline,
)
from ._weld import check_sewable
from .drag import DragParams, DragSession, Grab, MoveStats, ReleaseStats
from .drags import (
    Drags,
    DragStep,
    StepResult,
    apply_drags,
    drags_from_dict,
    drags_to_dict,
    drags_to_json,
    read_drags,
    write_drags,
)
from .outcome import on_body_failures, target_misses
from .perturb import HandPerturbation, perturb_strokes
from .strokes import (
    FORMAT,
    MAX_SURFACE_DISTANCE_M,
    PIECE_TOLERANCE_CM,
    VERSION,
    BodyStroke,
    PatternStroke,
    StrokePair,
    Strokes,
    check_strokes,
    in_file_frame,
    in_piece_frame,
    read_strokes,
    resolve_strokes,
    strokes_from_dict,
    strokes_to_dict,
    strokes_to_json,
    triangles_crossed,
    write_strokes,
)
from .suggest import SuggestParams, suggest_strokes
from .wrap import DressedGarment, WrapParams, wrap
from .wrap_settings import (
    CloseSettings,
    DrapeSettings,
    GrowSettings,
    LengthSettings,
    SettleSettings,
    TetherSettings,
    UntangleSettings,
)


def packaged_strokes_path(name: str = "kimono_default") -> Path:
    """Path of a strokes file shipped in kitsuke/assets/strokes (`name` without .json)."""
    ref = resources.files("kitsuke.assets") / "strokes" / f"{name}.json"
    return Path(str(ref))


def load_packaged_strokes(name: str = "kimono_default") -> Strokes:
    """Read a packaged strokes file (src/kitsuke/assets/strokes/, see its SOURCES.md):

    - "kimono_default": the kimono `kitsuke.pattern.default_kimono()` on `default_body()`;
    - "shirt_mean_all", "hoody_mean_all": GarmentCode's shirt and hoody on GarmentCode's mean_all body;
    - "tshirt_default": the FreeSewing Teagan T-shirt (sewn from its SVG) on `default_body()`.
    """
    return read_strokes(packaged_strokes_path(name))


__all__ = [
    "check_sewable",
    "HandPerturbation",
    "SuggestParams",
    "on_body_failures",
    "perturb_strokes",
    "suggest_strokes",
    "target_misses",
    "DragParams",
    "DragSession",
    "DragStep",
    "Drags",
    "Grab",
    "MoveStats",
    "ReleaseStats",
    "StepResult",
    "apply_drags",
    "drags_from_dict",
    "drags_to_dict",
    "drags_to_json",
    "read_drags",
    "write_drags",
    "DressedGarment",
    "WrapParams",
    "GrowSettings",
    "CloseSettings",
    "SettleSettings",
    "DrapeSettings",
    "LengthSettings",
    "TetherSettings",
    "UntangleSettings",
    "PolishSettings",
    "wrap",
    "FORMAT",
    "MAX_SURFACE_DISTANCE_M",
    "PIECE_TOLERANCE_CM",
    "VERSION",
    "BodyStroke",
    "PatternStroke",
    "StrokePair",
    "Strokes",
    "arc_length",
    "arc_parameters",
    "check_strokes",
    "in_file_frame",
    "in_piece_frame",
    "densify_polyline",
    "interpolate_polyline",
    "load_packaged_strokes",
    "packaged_strokes_path",
    "read_strokes",
    "resample_on_surface",
    "resample_polyline",
    "resolve_strokes",
    "stroke_coordinates",
    "strokes_from_dict",
    "strokes_to_dict",
    "strokes_to_json",
    "surface_length",
    "surface_polyline",
    "triangles_crossed",
    "write_strokes",
]
