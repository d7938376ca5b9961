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

By default the strokes place the garment and it then settles under gravity (the paper's way), each pattern
stroke kept within 8 mm of its body stroke (--stroke-reach; 0 lets it settle freely, a centimetre or two away).
--hold-strokes keeps the garment hanging from the strokes exactly instead.

A kimono pattern (from `kitsuke pattern kimono`) is dressed the way the demo dresses it: its sleeves hang below
the arms (--hang 2) and, on a rigged body (`default`), its waist is held where the obi goes while it settles.

Outputs: OUT.glb for viewers (garment, double-sided, plus the body); --obj the checkable OBJ (v = world metres,
vt = pattern metres, seam vertices shared, one `# kitsuke piece` line per piece); --report the quality report (JSON:
penetration, strain, seam gap, inverted triangles, stroke residuals, timings); --png a front/side/back picture.
The command exits 0 when the garment is written, whether or not every quality target is met: the targets it
misses are said on stderr and in the report ("targets_missed"). When the result is not a garment on the body
(non-finite, a piece off the body, torn cloth, a stroke far from where it was drawn) it exits 1 with one line
naming the stage and the piece or stroke, and writes nothing (--keep-failed writes it as OUT.failed.glb ...).
Before giving up it dresses the garment again: with its pieces laid where the pattern's placement puts them, then
with its seams sewn a little at a time (slower, never through a limb); stderr says which try was kept.

Re-wrap: give --garment (a dressed OBJ written by --obj) instead of --pattern, and a strokes file with
"target": "garment" (its pattern strokes on the garment's pieces, cm; its 3D strokes drawn on the garment where
that part should go). The stroke triangles are laid along the new strokes, the rest follows, attenuated towards
the pins (--pin X,Y,Z, metres, snapped to the nearest garment vertex, repeatable), which do not move at all.

examples:
  kitsuke dress --body mean_all.obj --pattern shirt_mean_specification.json \\
                --strokes shirt_mean_all.json -o shirt.glb --obj shirt.obj --report shirt.json --png shirt.png
  kitsuke pattern kimono --fit-height 1.666 -o kimono.json
  kitsuke dress --body default --pattern kimono.json --strokes src/kitsuke/assets/strokes/kimono_default.json \\
                -o kimono.glb --png kimono.png
  kitsuke dress --body default --garment dressed.obj --strokes lift_sleeve.json \\
                --pin 0,1.0,0.15 --pin 0,1.0,-0.15 -o rewrapped.glb --obj rewrapped.obj
"""


def register(parser: argparse.ArgumentParser) -> None:
    parser.description = "Dress a body with a garment: wrap the pattern so the strokes meet, then let it settle."
    parser.epilog = EPILOG
    parser.formatter_class = argparse.RawDescriptionHelpFormatter
    parser.add_argument("--body", required=True, metavar="BODY", help="body mesh file or `default`")
    what = parser.add_mutually_exclusive_group(required=True)
    what.add_argument("--pattern", metavar="PATTERN", help="pattern to dress: kitsuke/GarmentCode JSON, SVG")
    what.add_argument("--garment", metavar="DRESSED.obj", help="re-wrap this dressed garment (OBJ from --obj)")
    parser.add_argument("--strokes", required=True, metavar="STROKES", help="kitsuke strokes JSON")
    parser.add_argument("-o", "--output", required=True, metavar="OUT.glb", help="GLB output (garment + body)")
    parser.add_argument("--obj", metavar="OUT.obj", help="also write the SPEC 3.3 OBJ (vt = pattern metres)")
    parser.add_argument("--report", metavar="REPORT.json", help="also write the quality report")
    parser.add_argument("--png", metavar="VIEWS.png", help="also write a front/side/back picture")
    parser.add_argument(
        "--keep-failed",
        action="store_true",
        help="when the wrap fails (exit 1: the result is not a garment on the body), still write what it made, "
        "as OUT.failed.glb (and .failed.obj / .json / .png), for inspection",
    )
    parser.add_argument(
        "--pin",
        action="append",
        default=[],
        metavar="X,Y,Z",
        help="re-wrap only: hold the garment vertex nearest this point (metres; repeatable; write "
        "--pin=-0.1,1.0,0.15 when X is negative)",
    )
    parser.add_argument(
        "--edge-length",
        type=float,
        default=1.5,
        metavar="CM",
        help="target triangle edge length of the garment mesh, cm (default 1.5, what the shipped strokes are "
        "checked at; coarser is faster, and where a coarse mesh catches on an arm the report says where)",
    )
    parser.add_argument(
        "--hold-strokes",
        action="store_true",
        help="keep the garment where the strokes put it (it hangs from them) instead of letting it settle "
        "freely: strokes met within millimetres, more strain where they ask for more than the pattern gives",
    )
    parser.add_argument(
        "--hang",
        type=float,
        default=None,
        metavar="STRENGTH",
        help="how strongly cloth that grows off the body turns down as it grows (default 2 for a kimono "
        "pattern, whose wide sleeves then hang as bags below the arms; 0 otherwise: fitted garments grow "
        "straight on, the paper's way)",
    )
    parser.add_argument(
        "--stroke-reach",
        type=float,
        default=8.0,
        metavar="MM",
        help="how far a pattern stroke may settle from its body stroke, mm (default 8; 0: settle freely)",
    )
    parser.add_argument(
        "--no-polish",
        action="store_true",
        help="skip the last step, the polish (strain capped at 4.5 %%, finer triangles where a crease folds; a "
        "re-wrap's without refinement): about twice as fast (GarmentCode's shirt: 1.0 instead of 1.8 s of wrap) "
        "but the max edge strain stays where the settle left it (the shirt: 28 %% instead of 4.5 %%)",
    )
    parser.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        dest="settings",
        help="change one of the wrap's settings by its dotted name, applied after the options above (repeatable; "
        "e.g. --set settle.method=global --set polish.passes=1 --set grow.hang=1.5); the groups are grow, close, "
        "settle, drape, lengths, tethers, untangle and polish (kitsuke.dressing.WrapParams; --set drape.seconds=0 "
        "skips the drape of hanging cloth)",
    )
    add_body_options(parser)
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from ..cloth import precompile_in_background
    from ..dressing import check_strokes, read_strokes, target_misses
    from ..dressing.export import write_garment_outputs
    from ..dressing.options import DressOptions, parse_setting
    from ..dressing.wrap import DressedGarment, wrap
    from ..errors import ComputationError, InputError
    from ..pattern import load_pattern

    inputs = [args.body, args.pattern or args.garment, args.strokes]
    glb = checked_output(args.output, inputs, suffixes=(".glb",))
    obj, report, png = (
        checked_output(extra, inputs, suffixes=(suffix,)) if extra else None
        for extra, suffix in ((args.obj, ".obj"), (args.report, ".json"), (args.png, ".png"))
    )
    outs = [o for o in (glb, obj, report, png) if o is not None]
    if len({o.resolve() for o in outs}) != len(outs):
        raise InputError("the output files must be different")
    options = DressOptions(
        edge_length=args.edge_length,
        stroke_reach=args.stroke_reach,
        hold_strokes=args.hold_strokes,
        hang=args.hang,
        no_polish=args.no_polish,
        settings=tuple(parse_setting(text) for text in args.settings),
    )
    options.check(spell=lambda name: "--set" if name == "settings" else "--" + name.replace("_", "-"))
    if args.garment:
        if args.stroke_reach != 8.0:
            raise InputError("--stroke-reach is for a wrap: a re-wrap (--garment) holds its strokes already")
        if args.hold_strokes:
            raise InputError("--hold-strokes is for a wrap: a re-wrap (--garment) holds its strokes already")
        if args.hang is not None:
            raise InputError("--hang is for a wrap: a re-wrap (--garment) moves cloth already grown")
        if args.settings:
            raise InputError("--set changes the wrap's settings: a re-wrap (--garment) has its own")
        return _rewrap(args, outs)
    if args.pin:
        raise InputError("--pin holds part of a dressed garment: use it with --garment (a re-wrap)")
    # Cheap checks first: a bad pattern or strokes file fails before the body is loaded.
    pattern = load_pattern(args.pattern)
    strokes = read_strokes(args.strokes)
    check_strokes(strokes, pattern)
    if not args.no_polish:
        # The first run after an install: compile the polish (and a kimono's layer order) on the other core.
        precompile_in_background(layers=bool(pattern.meta.get("layers")))
    body = body_from_args(args)
    try:
        garment = wrap(body, pattern, strokes, params=options.wrap_params(body, pattern))
    except ComputationError as e:
        if args.keep_failed and isinstance(e.result, DressedGarment):
            failed = [None if o is None else o.with_suffix(".failed" + o.suffix) for o in (glb, obj, report, png)]
            write_garment_outputs(e.result, body.mesh, *failed)
            print(f"kept the failed result as {failed[0]} for inspection", file=sys.stderr)
        raise
    write_garment_outputs(garment, body.mesh, glb, obj, report, png)
    for name, width in garment.left_out.items():
        print(f"left out piece {name!r}: a sliver {width * 10:.2g} mm wide on average", file=sys.stderr)
    if garment.redone_after:
        laid = "every piece" if set(garment.laid) >= set(garment.piece_names) else ", ".join(garment.laid)
        how = " and ".join(
            ([f"{laid} laid at the placement"] if garment.laid else []) + (["its seams sewn"] if garment.sewn else [])
        )
        print(f"first try: {garment.redone_after}; dressed again with {how}", file=sys.stderr)
    misses = target_misses(garment)
    verdict = "all quality targets met" if not misses else "targets missed: " + "; ".join(misses)
    seconds = garment.timings.get("wrap", 0.0) + garment.timings.get("first try", 0.0)
    print(f"wrote {args.output}: {garment.n_vertices} vertices, wrap {seconds:.2f} s; {verdict}", file=sys.stderr)
    return 0


def _pin_points(values: list[str]) -> list[list[float]]:
    from ..errors import InputError

    pins = []
    for v in values:
        try:
            xyz = [float(c) for c in v.split(",")]
        except ValueError:
            xyz = []
        if len(xyz) != 3:
            raise InputError(f"--pin must be X,Y,Z in metres, got {v!r}")
        pins.append(xyz)
    return pins


def _rewrap(args: argparse.Namespace, outs: list) -> int:
    from .._files import write_json_atomic
    from ..dressing import read_strokes
    from ..dressing.export import read_garment_obj, write_garment_glb, write_garment_obj, write_garment_png
    from ..dressing.rewrap import RewrapParams, rewrap

    pins = _pin_points(args.pin)
    garment = read_garment_obj(args.garment)
    strokes = read_strokes(args.strokes)
    body = body_from_args(args)
    params = RewrapParams(polish_rounds=0) if args.no_polish else None
    result = rewrap(body, garment, strokes, pins=pins, params=params)
    write_garment_glb(result.garment, outs[0], body=body.mesh)
    if args.obj:
        write_garment_obj(result.garment, args.obj)
    if args.report:
        write_json_atomic(args.report, result.summary())
    if args.png:
        write_garment_png(result.garment, body.mesh, args.png)
    r = result.report
    verdict = "all quality targets met" if r.ok else "targets missed: " + ", ".join(r.failures())
    print(
        f"wrote {args.output}: re-wrapped {len(result.stroke_ids)} stroke(s), moved up to "
        f"{result.moved_m.max() * 100:.1f} cm, {int(result.pinned.sum())} pinned vertices still; {verdict}",
        file=sys.stderr,
    )
    return 0
