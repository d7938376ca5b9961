"""Offscreen rendering of meshes (body and/or garments) to images and PNG files.

moderngl on a headless EGL context (Mesa llvmpipe is enough; Debian packages libegl1 and libgl1-mesa-dri).
Conventions: Y up, the character faces +Z; "front" looks from +Z, "side" from the character's left (+X).

    from kitsuke.render import Renderer, render, render_sheet, write_png
    image = render([body, garment], view="front")            # (1000, 800, 3) uint8, shared context
    with Renderer() as r:                                      # own context, reused across calls
        write_png("side.png", r.render(body, view="side", background=None))   # RGBA, transparent
"""

from .camera import VIEWS, Camera, View, frame_camera
from .offscreen import (
    BACKGROUND,
    BODY_COLOR,
    DEFAULT_SIZE,
    GARMENT_COLORS,
    ColorLike,
    Renderer,
    default_renderer,
    parse_color,
    read_texture,
    render,
    write_png,
)
from .sheet import SHEET_VIEWS, contact_sheet, render_sheet, render_views

__all__ = [
    "BACKGROUND",
    "BODY_COLOR",
    "DEFAULT_SIZE",
    "GARMENT_COLORS",
    "SHEET_VIEWS",
    "VIEWS",
    "Camera",
    "ColorLike",
    "Renderer",
    "View",
    "contact_sheet",
    "default_renderer",
    "frame_camera",
    "parse_color",
    "read_texture",
    "render",
    "render_sheet",
    "render_views",
    "write_png",
]
