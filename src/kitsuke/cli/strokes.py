"""`kitsuke strokes ...`: propose and check stroke files (SPEC §3.2)."""

from __future__ import annotations

import argparse
import dataclasses
import sys

from ._common import add_body_options, body_from_args, checked_output

SUGGEST_EPILOG = """\
The pattern must say where its pieces go: a GarmentCode specification places every panel around its body, a
kimono from `kitsuke pattern kimono` hangs its pieces as on a kimono stand. Each piece large enough to matter gets
one stroke along its long axis through its middle, inside the piece; its body stroke is where the placed piece
meets the body along its normal, as long as the pattern stroke. Smaller pieces (cuffs, waistbands, collars) get
none: in the wrap they follow their seams. The garment is then dressed once, quickly, and each body stroke moved
to where its cloth came to rest; a garment resting tighter than the body round it (a skirt cut for the waist that
the placement lays at the hips) is raised, strokes and all, until it fits (--no-raise: left where it rests).
Pattern points are written in the pattern file's own coordinates (for GarmentCode, its panel coordinates), as a
user would draw them. Open the result in the app or any editor, change what you like, then dress.

examples:
  kitsuke strokes suggest --body mean_all.obj --pattern shirt_mean_specification.json -o shirt_strokes.json
  kitsuke dress --body mean_all.obj --pattern shirt_mean_specification.json --strokes shirt_strokes.json -o s.glb
"""

CHECK_EPILOG = """\
Checks a strokes file against its pattern (each pattern stroke on its piece) and its body (each body point within
5 cm of the surface, each laser ray hitting it) without dressing; prints one line per stroke: its piece, its two
lengths and their ratio. Exit 2 with one line naming the file and the stroke on the first problem.

example:
  kitsuke strokes check --body mean_all.obj --pattern shirt_mean_specification.json --strokes shirt.json
"""


def register(parser: argparse.ArgumentParser) -> None:
    parser.formatter_class = argparse.RawDescriptionHelpFormatter
    sub = parser.add_subparsers(dest="verb", metavar="<verb>")
    p = sub.add_parser(
        "suggest",
        help="propose a stroke set from the pattern's placement",
        description="Propose stroke pairs for a pattern on a body from the placement the pattern carries.",
        epilog=SUGGEST_EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--body", required=True, metavar="BODY", help="body mesh file or `default`")
    p.add_argument("--pattern", required=True, metavar="PATTERN", help="kitsuke/GarmentCode JSON with placements")
    p.add_argument("-o", "--output", required=True, metavar="STROKES.json", help="the strokes file to write")
    p.add_argument(
        "--min-area",
        type=float,
        default=None,
        metavar="SHARE",
        help="a piece gets a stroke when its area is at least this share of the largest piece's (default 0.15)",
    )
    p.add_argument(
        "--min-area-cm2",
        type=float,
        default=None,
        metavar="CM2",
        help="... or at least this many cm² (default 500: a bodice's panels beside a skirt ten times their size)",
    )
    p.add_argument(
        "--no-raise",
        action="store_true",
        help="leave a garment where it rests even when it is tighter there than the body round it",
    )
    add_body_options(p)
    p.set_defaults(run=run_suggest)

    p = sub.add_parser(
        "check",
        help="check a strokes file against its pattern and body",
        description="Check stroke pairs against the pattern and the body without dressing.",
        epilog=CHECK_EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--body", required=True, metavar="BODY", help="body mesh file or `default`")
    p.add_argument("--pattern", required=True, metavar="PATTERN", help="pattern file")
    p.add_argument("--strokes", required=True, metavar="STROKES", help="kitsuke strokes JSON")
    add_body_options(p)
    p.set_defaults(run=run_check)


def run_suggest(args: argparse.Namespace) -> int:
    from ..dressing import SuggestParams, suggest_strokes, write_strokes
    from ..errors import InputError
    from ..pattern import load_pattern

    out = checked_output(args.output, [args.body, args.pattern], suffixes=(".json",))
    if args.min_area is not None and not 0.0 <= args.min_area <= 1.0:
        raise InputError(f"--min-area must be a share between 0 and 1, got {args.min_area}")
    pattern = load_pattern(args.pattern)
    params = SuggestParams(fit=not args.no_raise)
    if args.min_area is not None:
        params = dataclasses.replace(params, min_area_share=args.min_area)
    if args.min_area_cm2 is not None:
        if not args.min_area_cm2 >= 0.0:
            raise InputError(f"--min-area-cm2 must be an area in cm² (>= 0), got {args.min_area_cm2}")
        params = dataclasses.replace(params, min_area_cm2=args.min_area_cm2)
    body = body_from_args(args)
    try:
        strokes = suggest_strokes(body, pattern, params=params)
    except InputError as e:
        raise InputError(e.message, args.pattern) from None
    strokes.meta["body"] = args.body
    write_strokes(strokes, out)
    pieces = ", ".join(p.pattern.piece for p in strokes.pairs)
    raised = strokes.meta.get("raised_m", 0.0)
    fit = f"; raised {100 * raised:.0f} cm from where it rested, to fit the body" if raised else ""
    print(f"wrote {out}: {len(strokes)} stroke pair(s) on {pieces}{fit}", file=sys.stderr)
    return 0


def run_check(args: argparse.Namespace) -> int:
    from ..dressing import arc_length, read_strokes, resolve_strokes
    from ..geometry.surface import Surface
    from ..pattern import load_pattern

    pattern = load_pattern(args.pattern)
    strokes = read_strokes(args.strokes)
    body = body_from_args(args)
    resolved = resolve_strokes(strokes, pattern, Surface(body.mesh))
    for p in resolved.pairs:
        lb = float(arc_length(p.body.surface_points)[-1])
        lp = p.pattern.length_cm / 100.0
        print(
            f"stroke {p.id}: piece {p.pattern.piece}, pattern {100 * lp:.1f} cm, body {100 * lb:.1f} cm, "
            f"ratio {lb / lp:.2f}"
        )
    print(f"{args.strokes}: ok: {len(resolved)} stroke pair(s)", file=sys.stderr)
    return 0
