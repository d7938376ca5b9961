"""`kitsuke dress`: put a garment on a body from a pattern and stroke pairs (SPEC §4), write GLB/OBJ/report/PNG."""

from __future__ import annotations

import argparse
import sys

from ._common import add_body_options, body_from_args, checked_output

EPILOG = """\
BODY is a mesh file (OBJ, GLB, PLY; units and axes detected) or `default` (the built-in MakeHuman body).
PATTERN is a kitsuke pattern JSON, a GarmentCode specification JSON or an SVG. STROKES is a kitsuke strokes JSON
(SPEC 3.2): numbered pairs of a stroke on a pattern piece (cm) and a stroke on the body (points in metres, or laser
rays). Stroke files ship with kitsuke for the examples below (see kitsuke/assets/strokes).

Outputs: OUT.glb for viewers (garment, double-sided, plus the body); --obj the checkable OBJ (v = world metres,
vt = pattern metres, seam vertices shared, one `# kitsuke piece` line per piece); --report the quality report (JSON:
penetration, strain, seam gap, inverted triangles, stroke residuals, timings); --png a front/side/back picture.
The command exits 0 when the garment is written, whether or not every quality target is met: read the report.

examples:
  kitsuke dress --body mean_all.obj --pattern shirt_mean_specification.json \\
                --strokes shirt_mean_all.json -o shirt.glb --obj shirt.obj --report shirt.json --png shirt.png
"""


def register(parser: argparse.ArgumentParser) -> None:
    parser.description = "Dress a body with a garment: wrap the pattern so the strokes meet, then let it settle."
    parser.epilog = EPILOG
    parser.formatter_class = argparse.RawDescriptionHelpFormatter
    parser.add_argument("--body", required=True, metavar="BODY", help="body mesh file or `default`")
    parser.add_argument("--pattern", required=True, metavar="PATTERN", help="pattern: kitsuke/GarmentCode JSON, SVG")
    parser.add_argument("--strokes", required=True, metavar="STROKES", help="kitsuke strokes JSON")
    parser.add_argument("-o", "--output", required=True, metavar="OUT.glb", help="GLB output (garment + body)")
    parser.add_argument("--obj", metavar="OUT.obj", help="also write the SPEC 3.3 OBJ (vt = pattern metres)")
    parser.add_argument("--report", metavar="REPORT.json", help="also write the quality report")
    parser.add_argument("--png", metavar="VIEWS.png", help="also write a front/side/back picture")
    parser.add_argument(
        "--edge-length",
        type=float,
        default=1.5,
        metavar="CM",
        help="target triangle edge length of the garment mesh, cm (default 1.5)",
    )
    add_body_options(parser)
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from ..dressing import check_strokes, read_strokes
    from ..dressing.export import write_garment_glb, write_garment_obj, write_garment_png, write_garment_report
    from ..dressing.wrap import WrapParams, wrap
    from ..errors import InputError
    from ..pattern import load_pattern

    inputs = [args.body, args.pattern, args.strokes]
    outs = [checked_output(args.output, inputs, suffixes=(".glb",))]
    for extra, suffix in ((args.obj, ".obj"), (args.report, ".json"), (args.png, ".png")):
        if extra:
            outs.append(checked_output(extra, inputs, suffixes=(suffix,)))
    if len({o.resolve() for o in outs}) != len(outs):
        raise InputError("the output files must be different")
    if not 0.2 <= args.edge_length <= 10:
        raise InputError(f"--edge-length must be between 0.2 and 10 cm, got {args.edge_length}")
    # Cheap checks first: a bad pattern or strokes file fails before the body is loaded.
    pattern = load_pattern(args.pattern)
    strokes = read_strokes(args.strokes)
    check_strokes(strokes, pattern)
    body = body_from_args(args)
    garment = wrap(body, pattern, strokes, params=WrapParams(edge_length_cm=args.edge_length))
    write_garment_glb(garment, outs[0], body=body.mesh)
    if args.obj:
        write_garment_obj(garment, args.obj)
    if args.report:
        write_garment_report(garment, args.report)
    if args.png:
        write_garment_png(garment, body.mesh, args.png)
    r = garment.report
    verdict = "" if r is None else ("all quality targets met" if r.ok else "targets missed: " + ", ".join(r.failures()))
    print(
        f"wrote {args.output}: {garment.n_vertices} vertices, wrap {garment.timings.get('wrap', 0.0):.2f} s; {verdict}",
        file=sys.stderr,
    )
    return 0
