"""`kitsuke pattern ...`: convert, inspect, validate, mesh and generate sewing patterns."""

from __future__ import annotations

import argparse
import json

from ._common import checked_output

FORMATS = """\
Pattern files: kitsuke JSON (format "kitsuke.pattern", SPEC §3.1), GarmentCode JSON specifications (told apart
from kitsuke JSON by their content) and SVG (closed paths become pieces; FreeSewing files: the "fabric" outlines,
in true size). Outputs by extension: .json (kitsuke JSON), .svg (true-size picture, 1 unit = 1 cm) and .png
(the same picture). Lengths are in cm.
"""

GROUP_EPILOG = (
    FORMATS
    + """
examples:
  kitsuke pattern convert shirt_mean_specification.json shirt.json
  kitsuke pattern convert teagan_tshirt.svg teagan.png
  kitsuke pattern info shirt.json
  kitsuke pattern kimono --yuki 66 --shoulder 32 -o kimono.json
  kitsuke pattern mesh kimono.json -o kimono.obj --edge-length 1.5
  kitsuke pattern texture -o asanoha.png --motif asanoha --repeat-cm 3
"""
)


def _picture_options(p: argparse.ArgumentParser) -> None:
    g = p.add_argument_group("pictures (.svg / .png outputs)")
    g.add_argument(
        "--texture",
        choices=["asanoha", "seigaiha"],
        default=None,
        help="fill the pieces with a textile motif drawn through pattern coordinates (default: plain)",
    )
    g.add_argument("--repeat-cm", type=float, metavar="CM", default=3.0, help="motif size, cm (default 3)")
    g.add_argument("--palette", default="indigo", help="texture colours: indigo, crimson, sakura, matcha")
    g.add_argument("--plain", action="store_true", help="pieces only: no labels, edge numbers, seams or legend")
    g.add_argument(
        "--max-px", type=int, metavar="PX", default=2400, help="PNG size: the longer side in pixels (default 2400)"
    )


def _picture_kwargs(args: argparse.Namespace, suffix: str) -> dict:
    if suffix == ".json":
        return {}
    kw = {"texture": args.texture, "repeat_cm": args.repeat_cm, "palette": args.palette, "annotate": not args.plain}
    if suffix == ".png":
        kw["max_px"] = args.max_px
    return kw


def _verb(sub, name: str, help_text: str, description: str, epilog: str) -> argparse.ArgumentParser:
    return sub.add_parser(
        name,
        help=help_text,
        description=description,
        epilog=epilog,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )


def register(parser: argparse.ArgumentParser) -> None:
    parser.epilog = GROUP_EPILOG
    parser.formatter_class = argparse.RawDescriptionHelpFormatter
    sub = parser.add_subparsers(dest="verb", metavar="<verb>")

    p = _verb(
        sub,
        "convert",
        "convert a pattern between kitsuke JSON, GarmentCode JSON, SVG and PNG",
        "Read a pattern (kitsuke JSON, GarmentCode JSON or SVG), validate it, and write it by the output's "
        "extension. Seam length mismatches above 1 % are reported on stderr.",
        FORMATS + "\nexamples:\n  kitsuke pattern convert hoody_mean_specification.json hoody.svg\n"
        "  kitsuke pattern convert kimono.json kimono.png --texture asanoha\n",
    )
    p.add_argument("input", metavar="IN", help="pattern file (.json or .svg)")
    p.add_argument("output", metavar="OUT", help="output file (.json, .svg or .png)")
    _picture_options(p)
    p.set_defaults(run=run_convert)

    p = _verb(
        sub,
        "info",
        "print a JSON summary: pieces, areas, seams, warnings",
        "Read and validate a pattern and print a JSON summary on stdout: pieces (edges, area cm², size), "
        "seams (edges, lengths, reversed) and validation warnings.",
        FORMATS + "\nexample:\n  kitsuke pattern info shirt_mean_specification.json\n",
    )
    p.add_argument("pattern", metavar="PATTERN", help="pattern file")
    p.set_defaults(run=run_info)

    p = _verb(
        sub,
        "validate",
        "check a pattern; exit 2 on errors, list warnings",
        "Check a pattern file. Errors (unreadable file, self-intersecting or zero-area outline, clockwise "
        "outline, seams naming unknown pieces or edges, duplicate names, seams that cannot be sewn into one "
        "garment surface, which `kitsuke dress` would refuse) give one line on stderr and exit code 2; "
        "warnings (seam edges differing by more than 1 %; where they differ by more than 3 % and 1 cm, `dress` "
        "gathers the longer side; a piece less than 5 mm wide on average) are printed and the exit code is 0.",
        FORMATS + "\nexample:\n  kitsuke pattern validate my_pattern.json\n",
    )
    p.add_argument("pattern", metavar="PATTERN", help="pattern file")
    p.set_defaults(run=run_validate)

    p = _verb(
        sub,
        "kimono",
        "make a kimono pattern of given measurements (cm)",
        "Generate an unlined kimono pattern (2 body panels, 2 okumi, 2 sleeves, collar; 21 seams) with "
        "placement hints around a standing 1.67 m body. Defaults are the standard size: length 158, "
        "yuki 63, shoulder 31, sleeve width 32 (= yuki - shoulder), sleeve depth 49, bolt width 37.",
        "Output by extension: .json (the pattern), .svg or .png (its picture).\n\nexamples:\n"
        "  kitsuke pattern kimono -o kimono.json\n"
        "  kitsuke pattern kimono --length 150 --yuki 66 --shoulder 32 -o kimono.json\n"
        "  kitsuke pattern kimono --sleeve-depth 110 -o furisode.png --texture asanoha\n"
        "  kitsuke pattern kimono --fit-height 1.666 -o kimono.json   # the demo's kimono (packaged strokes fit it)\n",
    )
    _size_arguments(p)
    p.add_argument(
        "--fit-height",
        type=float,
        metavar="M",
        default=None,
        help="cut the length for a wearer this tall (metres), worn without an ohashori fold (replaces --length); "
        "1.666 gives the default body's kimono, the one the packaged strokes `kimono_default` place",
    )
    p.add_argument("-o", "--output", required=True, metavar="OUT", help="output file (.json, .svg or .png)")
    _picture_options(p)
    p.set_defaults(run=run_kimono)

    p = _verb(
        sub,
        "mesh",
        "triangulate a pattern (Triangle) and write OBJ",
        "Mesh every piece with Shewchuk's Triangle at a target edge length and minimum angle; both sides of "
        "every seam get the same number of boundary vertices. Writes OBJ: v = placed positions (metres, "
        "around the body, from the placement hints), vt = pattern position in metres, a group and a "
        "`# kitsuke piece <name> <first_face> <last_face>` comment per piece, and the seam vertex pairs as "
        "`# kitsuke seam-pairs` comments. Prints a JSON summary with quality figures.",
        FORMATS + "\nexamples:\n  kitsuke pattern mesh kimono.json -o kimono.obj\n"
        "  kitsuke pattern mesh shirt_mean_specification.json -o shirt.obj --edge-length 1.0 --flat\n",
    )
    p.add_argument("pattern", metavar="PATTERN", help="pattern file")
    p.add_argument("-o", "--output", required=True, metavar="OBJ", help="output mesh (.obj)")
    p.add_argument("--edge-length", type=float, metavar="CM", default=1.5, help="target edge length, cm (default 1.5)")
    p.add_argument(
        "--min-angle", type=float, metavar="DEG", default=25.0, help="minimum triangle angle, degrees (default 25)"
    )
    p.add_argument("--flat", action="store_true", help="write the flat pattern (x, y, 0 in metres) instead of placed")
    p.set_defaults(run=run_mesh)

    p = _verb(
        sub,
        "texture",
        "draw a seamless textile tile (asanoha, seigaiha) as PNG",
        "Draw one seamless tile of a traditional repeat. Map it with uv = pattern cm / tile size (printed on "
        "stdout as JSON) and REPEAT wrapping, so the motif is the same size on every piece.",
        "examples:\n  kitsuke pattern texture -o asanoha.png\n"
        "  kitsuke pattern texture -o waves.png --motif seigaiha --palette crimson --repeat-cm 4\n",
    )
    p.add_argument("-o", "--output", required=True, metavar="PNG", help="output image (.png)")
    p.add_argument("--motif", choices=["asanoha", "seigaiha"], default="asanoha", help="the repeat (default asanoha)")
    p.add_argument("--repeat-cm", type=float, metavar="CM", default=3.0, help="motif size, cm (default 3)")
    p.add_argument("--px-per-cm", type=float, metavar="PX", default=64.0, help="resolution (default 64 px per cm)")
    p.add_argument("--palette", default="indigo", help="indigo, crimson, sakura or matcha (default indigo)")
    p.set_defaults(run=run_texture)


#: KimonoSize's defaults, repeated here so that `kitsuke --help` does not import numpy (a test keeps them equal).
KIMONO_DEFAULTS = {
    "length": 158.0,
    "yuki": 63.0,
    "shoulder": 31.0,
    "sleeve_depth": 49.0,
    "bolt_width": 37.0,
    "sleeve_round": 2.0,
}


def _size_arguments(p: argparse.ArgumentParser) -> None:
    d = KIMONO_DEFAULTS
    g = p.add_argument_group("measurements (finished, cm)")
    g.add_argument(
        "--length",
        type=float,
        metavar="CM",
        default=d["length"],
        help=f"身丈 length, shoulder to hem (default {d['length']:g})",
    )
    g.add_argument(
        "--yuki",
        type=float,
        default=d["yuki"],
        help=f"裄 centre back to sleeve end = shoulder + sleeve width (default {d['yuki']:g})",
    )
    g.add_argument(
        "--shoulder",
        type=float,
        default=d["shoulder"],
        help=f"肩幅 shoulder width, centre back to the sleeve seam (default {d['shoulder']:g})",
    )
    g.add_argument(
        "--sleeve-width",
        type=float,
        default=None,
        help="袖幅 sleeve width (default: yuki - shoulder, 32); if given, must equal it",
    )
    g.add_argument(
        "--sleeve-depth",
        type=float,
        default=d["sleeve_depth"],
        help=f"袖丈 sleeve depth, crease to bottom (default {d['sleeve_depth']:g}; furisode ~114)",
    )
    g.add_argument(
        "--sleeve-round",
        type=float,
        default=d["sleeve_round"],
        help=f"袖の丸み radius of the sleeve's rounded bottom corner at the cuff (default {d['sleeve_round']:g}, "
        "formal; everyday kimono 4-12; 0: square)",
    )
    g.add_argument(
        "--bolt-width",
        type=float,
        default=d["bolt_width"],
        help=f"width of the cloth bolt; pieces must fit it (default {d['bolt_width']:g}; usually 36-38)",
    )


def _print_warnings(issues) -> None:
    import sys

    for i in issues:
        print(f"kitsuke: warning: {i.message}", file=sys.stderr)


def _said_gathered(pattern, issues) -> list:
    """The issues, each length mismatch that `kitsuke dress` gathers saying so."""
    import dataclasses

    from ..dressing._gather import gathered_seams
    from ..dressing.wrap_settings import GatherSettings

    g = GatherSettings()
    gathered = set(gathered_seams(pattern, g.min_difference, g.min_cm))
    return [
        dataclasses.replace(i, message=i.message + "; dressed, its longer side is gathered")
        if i.code == "length-mismatch" and i.seam in gathered
        else i
        for i in issues
    ]


def run_convert(args: argparse.Namespace) -> int:
    from ..pattern import load_pattern_with_issues, save_pattern

    out = checked_output(args.output, [args.input], suffixes=(".json", ".svg", ".png"))
    pattern, issues = load_pattern_with_issues(args.input)
    _print_warnings(issues)
    save_pattern(pattern, out, **_picture_kwargs(args, out.suffix.lower()))
    return 0


def pattern_summary(pattern, issues) -> dict:
    import numpy as np

    pieces = []
    for p in pattern.pieces:
        lo, hi = p.bounds
        pieces.append(
            {
                "name": p.name,
                "edges": p.n_edges,
                "curved_edges": len(p.curves),
                "area_cm2": round(p.area, 3),
                "size_cm": [round(float(v), 3) for v in hi - lo],
                "flipped": p.flipped,
                "placed": p.placement is not None,
            }
        )
    seams = [
        {
            "a": str(s.a),
            "b": str(s.b),
            "reversed": s.reversed,
            "length_cm": [round(pattern.edge_length(s.a), 3), round(pattern.edge_length(s.b), 3)],
        }
        for s in pattern.seams
    ]
    return {
        "name": pattern.name,
        "pieces": pieces,
        "seams": seams,
        "total_area_cm2": round(float(np.sum([p.area for p in pattern.pieces])), 3),
        "warnings": [i.to_dict() for i in issues],
        "meta": pattern.meta,
    }


def run_info(args: argparse.Namespace) -> int:
    from ..pattern import load_pattern_with_issues

    pattern, issues = load_pattern_with_issues(args.pattern)
    print(json.dumps(pattern_summary(pattern, issues), indent=2, ensure_ascii=False))
    return 0


def run_validate(args: argparse.Namespace) -> int:
    from ..dressing import check_sewable
    from ..errors import InputError
    from ..pattern import load_pattern_with_issues

    pattern, issues = load_pattern_with_issues(args.pattern)
    try:
        check_sewable(pattern)  # what `dress` meshes and sews: the same refusals, here
    except InputError as e:
        raise InputError(e.message, args.pattern) from None
    _print_warnings(_said_gathered(pattern, issues))
    print(
        f"{args.pattern}: ok: {len(pattern.pieces)} pieces, {len(pattern.seams)} seams, "
        f"{len(issues)} warning{'s' * (len(issues) != 1)}"
    )
    return 0


def run_kimono(args: argparse.Namespace) -> int:
    from ..pattern import KimonoSize, fitted_size, make_kimono, save_pattern

    out = checked_output(args.output, [], suffixes=(".json", ".svg", ".png"))
    size = KimonoSize(
        length=args.length,
        yuki=args.yuki,
        shoulder=args.shoulder,
        sleeve_width=args.sleeve_width,
        sleeve_depth=args.sleeve_depth,
        bolt_width=args.bolt_width,
        sleeve_round=args.sleeve_round,
    )
    if args.fit_height is not None:
        size = fitted_size(args.fit_height, size)
    pattern = make_kimono(size)
    save_pattern(pattern, out, **_picture_kwargs(args, out.suffix.lower()))
    print(f"{out}: {pattern.meta['kimono']['label']}: {len(pattern.pieces)} pieces, {len(pattern.seams)} seams")
    return 0


def run_mesh(args: argparse.Namespace) -> int:
    import time

    from ..pattern import load_pattern, mesh_pattern, mesh_quality, write_pattern_obj

    out = checked_output(args.output, [args.pattern], suffixes=(".obj",))
    pattern = load_pattern(args.pattern)
    t0 = time.perf_counter()
    mesh = mesh_pattern(pattern, edge_length=args.edge_length, min_angle=args.min_angle)
    seconds = time.perf_counter() - t0
    write_pattern_obj(mesh, out, placed=not args.flat, seams=pattern.seams)
    summary = {
        "output": str(out),
        "pieces": len(mesh.piece_names),
        "vertices": mesh.n_vertices,
        "faces": mesh.n_faces,
        "seams": len(mesh.seam_vertices),
        "edge_length_cm": mesh.edge_length_cm,
        "seconds": round(seconds, 4),
        "quality": mesh_quality(mesh),
    }
    print(json.dumps(summary, indent=2))
    return 0


def run_texture(args: argparse.Namespace) -> int:
    import io

    from PIL import Image

    from .._files import write_bytes_atomic
    from ..pattern import kimono_texture, texture_tile_size_cm

    out = checked_output(args.output, [], suffixes=(".png",))
    img = kimono_texture(motif=args.motif, repeat_cm=args.repeat_cm, px_per_cm=args.px_per_cm, palette=args.palette)
    buf = io.BytesIO()
    Image.fromarray(img).save(buf, format="PNG", optimize=True)
    write_bytes_atomic(out, buf.getvalue())
    tw, th = texture_tile_size_cm(args.motif, args.repeat_cm)
    print(
        json.dumps(
            {
                "output": str(out),
                "pixels": [img.shape[1], img.shape[0]],
                "tile_cm": [tw, th],
                "uv": f"u = x_cm / {tw:g}, v = y_cm / {th:g} (REPEAT)",
            }
        )
    )
    return 0
