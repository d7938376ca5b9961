"""`kitsuke demo`: the built-in body and kimono, end to end, into a folder."""

from __future__ import annotations

import argparse

EPILOG = """\
Writes into OUT (default: out/): the default body as GLB, the standard kimono pattern as JSON, SVG and PNG (with
and without its asanoha texture), the meshed pattern as OBJ, and PNG renders of the body (front, side) and of the
kimono around it. Open the PNGs first.

example:
  kitsuke demo --out demo_out
"""


def register(parser: argparse.ArgumentParser) -> None:
    parser.description = "Run the built-in demo: default body + standard kimono -> files in a folder."
    parser.epilog = EPILOG
    parser.formatter_class = argparse.RawDescriptionHelpFormatter
    parser.add_argument("--out", default="out", metavar="DIR", help="output folder (default: out)")
    parser.add_argument("--size", default="800x1000", metavar="WxH", help="render size in pixels (default 800x1000)")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from ..demo import run_demo
    from ..errors import InputError

    try:
        w, h = (int(x) for x in args.size.lower().split("x"))
        if not (16 <= w <= 8192 and 16 <= h <= 8192):
            raise ValueError
    except ValueError:
        raise InputError(f"--size must be WxH in pixels (16-8192), got {args.size!r}") from None
    result = run_demo(args.out, size=(w, h))
    for path, what in result.files.items():
        print(f"  {path}  {what}")
    total = sum(result.timings_s.values())
    steps = ", ".join(f"{k} {v:.2f} s" for k, v in result.timings_s.items())
    print(f"kitsuke demo: wrote {len(result.files)} files to {args.out}/ in {total:.1f} s ({steps})")
    return 0
