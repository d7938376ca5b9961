"""`kitsuke render MESH... -o view.png`: offscreen PNG renders of meshes (a body and/or garments)."""

from __future__ import annotations

import argparse

from ._common import checked_output

VIEW_CHOICES = ("front", "side", "back", "left", "right", "three_quarter", "all")

EPILOG = """\
MESH is a mesh file (OBJ, GLB/glTF, PLY, STL, OFF) in metres, Y up, facing +Z, or `default` for the built-in
body. Several meshes are drawn together, e.g. a body and then a garment; the camera frames all of them.

Views (the character faces +Z): front = from +Z; side = left = from the character's left (+X);
right = from -X; back = from -Z; three_quarter = front-left at 45 degrees; all = front, side and back on one
labelled sheet. Lighting follows the camera (key light from the upper left). Garments are double-sided: their
inside is shaded too.

examples:
  kitsuke render body.obj -o front.png
  kitsuke render body.obj dressed.obj -o sheet.png --view all --size 600x750
  kitsuke render dressed.obj -o kimono.png --texture asanoha.png --view three_quarter
  kitsuke render body.glb -o side.png --view side --transparent --color "#c8b4a0"
"""


def register(parser: argparse.ArgumentParser) -> None:
    parser.description = (
        "Render meshes offscreen (OpenGL through EGL; Mesa's software renderer is enough) to a PNG image."
    )
    parser.epilog = EPILOG
    parser.formatter_class = argparse.RawDescriptionHelpFormatter
    parser.add_argument("meshes", nargs="+", metavar="MESH", help="mesh files, drawn together (or `default`)")
    parser.add_argument("-o", "--output", required=True, metavar="PNG", help="output image (.png)")
    parser.add_argument(
        "--view",
        default="front",
        choices=VIEW_CHOICES,
        help="where the camera stands (default: front); `all` = front, side and back side by side",
    )
    parser.add_argument(
        "--size",
        default="800x1000",
        metavar="WxH",
        help="image size in pixels, width x height (default: 800x1000; with --view all, per panel)",
    )
    parser.add_argument(
        "--texture",
        metavar="IMAGE",
        help="texture image (PNG/JPEG) for the LAST mesh, mapped through its UV coordinates (needs UVs)",
    )
    parser.add_argument(
        "--color",
        nargs="+",
        metavar="COLOR",
        help="one colour per mesh, in order: a name (navy) or #rrggbb (default: skin, then cloth colours)",
    )
    parser.add_argument("--wireframe", action="store_true", help="draw the triangle edges over the shading")
    parser.add_argument("--flat", action="store_true", help="flat shading (face normals) instead of smooth")
    bg = parser.add_mutually_exclusive_group()
    bg.add_argument(
        "--background",
        metavar="COLOR",
        help="solid background colour (default: a soft light-grey gradient)",
    )
    bg.add_argument("--transparent", action="store_true", help="transparent background (RGBA PNG; not with --view all)")
    parser.set_defaults(run=run_render)


def parse_size(text: str):
    """'800x1000' -> (800, 1000); InputError otherwise."""
    from ..errors import InputError

    parts = text.lower().replace("×", "x").split("x")
    try:
        w, h = (int(p) for p in parts)
    except ValueError:
        raise InputError(f"--size must be WIDTHxHEIGHT in pixels, like 800x1000, got {text!r}") from None
    if not (16 <= w <= 8192 and 16 <= h <= 8192):
        raise InputError(f"--size {text}: width and height must be 16..8192 pixels")
    return w, h


def _load(path: str):
    from ..geometry import load_mesh

    if path == "default":
        from ..body import default_body

        return default_body().mesh
    return load_mesh(path)


def run_render(args: argparse.Namespace) -> int:
    import numpy as np

    from ..errors import InputError
    from ..render import BACKGROUND, SHEET_VIEWS, default_renderer, read_texture, render_sheet, write_png

    inputs = list(args.meshes) + ([args.texture] if args.texture else [])
    out = checked_output(args.output, inputs, suffixes=(".png",))
    size = parse_size(args.size)
    if args.color and len(args.color) > len(args.meshes):
        raise InputError(f"{len(args.color)} colours given for {len(args.meshes)} meshes (--color)")
    if args.transparent and args.view == "all":
        raise InputError("--transparent needs a single --view, not `all`")
    meshes = [_load(p) for p in args.meshes]
    if args.texture:
        target = meshes[-1]
        if target.uv is None:
            raise InputError("has no UV coordinates, so --texture cannot be mapped onto it", args.meshes[-1])
        target.texture = read_texture(args.texture)
    options = dict(
        size=size,
        colors=args.color,
        wireframe=args.wireframe,
        shading="flat" if args.flat else "smooth",
        background=None if args.transparent else (args.background or BACKGROUND),
    )
    renderer = default_renderer()
    if args.view == "all":
        image = render_sheet(meshes, SHEET_VIEWS, renderer=renderer, **options)
    else:
        image = renderer.render(meshes, view=args.view, **options)
    write_png(out, np.ascontiguousarray(image), inputs=inputs)
    h, w = image.shape[:2]
    print(f"wrote {out} ({w}x{h}, view {args.view}, {sum(m.n_faces for m in meshes)} triangles)")
    return 0
