"""`kitsuke body ...`: inspect and convert body meshes."""

from __future__ import annotations

import argparse
import json

from ._common import add_body_options, body_from_args, checked_output

EPILOG = """\
BODY is a mesh file (OBJ, GLB/glTF, PLY) or the word `default` for the built-in rigged MakeHuman body.
Units (m, dm, cm, mm, in), the up axis and the facing are detected and converted to metres, Y up, facing +Z;
override them with --units/--up/--facing when a body is unusual (a child in cm, a T-pose, no feet).

examples:
  kitsuke body info default
  kitsuke body info scan.ply --units mm
  kitsuke body convert scan_zup.obj scan.glb        # metres, Y up, facing +Z
"""


def register(parser: argparse.ArgumentParser) -> None:
    parser.epilog = EPILOG
    parser.formatter_class = argparse.RawDescriptionHelpFormatter
    sub = parser.add_subparsers(dest="verb", metavar="<verb>")
    p = sub.add_parser(
        "info",
        help="print a JSON summary: size, height, conversion, watertight, holes, rig",
        description="Load a body, validate and convert it, and print a JSON summary on stdout.",
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("body", metavar="BODY", help="mesh file or `default`")
    add_body_options(p)
    p.set_defaults(run=run_info)

    p = sub.add_parser(
        "convert",
        help="write a body in metres, Y up, facing +Z (OBJ, GLB or PLY)",
        description="Load a body (detecting units and axes), and write it converted. The input is never overwritten.",
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("body", metavar="BODY", help="mesh file or `default`")
    p.add_argument("output", metavar="OUT", help="output mesh: .obj, .glb or .ply")
    add_body_options(p)
    p.set_defaults(run=run_convert)


def run_info(args: argparse.Namespace) -> int:
    body = body_from_args(args)
    print(json.dumps(body.info(), indent=2))
    return 0


def run_convert(args: argparse.Namespace) -> int:
    from ..geometry import save_mesh

    out = checked_output(args.output, [args.body], suffixes=(".obj", ".glb", ".ply"))
    body = body_from_args(args)
    save_mesh(body.mesh, out)
    notes = "; ".join(body.conversion.notes) or "no conversion needed"
    print(f"wrote {out} ({body.mesh.n_vertices} vertices, {body.height_m:.3f} m tall): {notes}")
    return 0
