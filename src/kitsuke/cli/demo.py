"""`kitsuke demo`: the built-in body and kimono, end to end, into a folder."""

from __future__ import annotations

import argparse

EPILOG = """\
Writes into OUT (default: out/): the default body as GLB, the kimono pattern (the standard size cut to the
default body) as JSON, SVG and PNG (with and without its asanoha texture), the meshed pattern as OBJ, PNG renders
of the body (front, side) and of the kimono around it, and the kimono DRESSED on the body with the packaged
strokes (wrap + settle, waist held where the obi goes): dressed.glb (textured, with the body), dressed.obj
(vt = pattern metres), dressed_report.json (strain, penetration, seam gap, stroke residuals) and dressed.png
(front / side / back). Open dressed.png first. Takes about 15 s on 2 cores.

example:
  kitsuke demo --out demo_out
"""


def register(parser: argparse.ArgumentParser) -> None:
    parser.description = "Run the built-in demo: dress the default body in the kimono -> files in a folder."
    parser.epilog = EPILOG
    parser.formatter_class = argparse.RawDescriptionHelpFormatter
    parser.add_argument("--out", default="out", metavar="DIR", help="output folder (default: out)")
    parser.add_argument("--size", default="800x1000", metavar="WxH", help="render size in pixels (default 800x1000)")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from ..cloth import precompile_in_background
    from ..demo import run_demo
    from ..errors import InputError

    try:
        w, h = (int(x) for x in args.size.lower().split("x"))
        if not (16 <= w <= 8192 and 16 <= h <= 8192):
            raise ValueError
    except ValueError:
        raise InputError(f"--size must be WxH in pixels (16-8192), got {args.size!r}") from None
    precompile_in_background(layers=True)  # the first run after an install: compile on the other core too
    result = run_demo(args.out, size=(w, h))
    for path, what in result.files.items():
        print(f"  {path}  {what}")
    total = sum(result.timings_s.values())
    steps = ", ".join(f"{k} {v:.2f} s" for k, v in result.timings_s.items())
    print(f"kitsuke demo: wrote {len(result.files)} files to {args.out}/ in {total:.1f} s ({steps})")
    return 0
