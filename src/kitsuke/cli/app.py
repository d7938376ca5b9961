"""`kitsuke app`: the browser app."""

from __future__ import annotations

import argparse

from ._common import add_body_options

EPILOG = """\
Opens a local web page with the body and the pattern's pieces side by side. Press and drag on a pattern piece to
draw a stroke, then press and drag on the body to draw where it goes: each pair gets a number and a colour. Drag
on empty space to turn the view. Wrap puts the garment on the body (a few seconds to a minute, its stage shown;
Cancel wrap stops it). Then drag the garment along the body, pin it with clicks, draw on it and re-wrap, or tick
Show strain. Edit the pattern in the panel: draw pieces by their corners, move, add and delete points, bend edges,
sew, turn pieces over. Save writes the garment (GLB, OBJ with pattern UVs, report), the strokes, the drags and the
pattern through the browser's downloads. Open another body, pattern or strokes file from the panel (at most 50 MB;
never a path on this machine).

It listens on 127.0.0.1 only unless --host says otherwise (0.0.0.0: every network this machine is on; anyone who
can reach the port can use the app). Each browser tab is its own session; the tabs' wraps run one at a time.

examples:
  kitsuke app                                             # the default body and kimono
  kitsuke app --pattern tests/data/pattern/shirt_mean_specification.json --port 8081
  kitsuke app --strokes out/kimono_strokes.json --no-browser
"""


def register(parser: argparse.ArgumentParser) -> None:
    parser.description = "The browser app: draw strokes, edit the pattern, wrap, drag, pin, save."
    parser.epilog = EPILOG
    parser.formatter_class = argparse.RawDescriptionHelpFormatter
    parser.add_argument("--body", default="default", metavar="BODY", help="body mesh file or `default`")
    parser.add_argument("--pattern", metavar="PATTERN", help="pattern: kitsuke/GarmentCode JSON, SVG (default kimono)")
    parser.add_argument("--strokes", metavar="STROKES", help="stroke pairs to start from (kitsuke strokes JSON)")
    parser.add_argument("--host", default="127.0.0.1", help="address to listen on (default 127.0.0.1: this machine)")
    parser.add_argument("--port", type=int, default=8080, help="port (default 8080; the next free one if taken)")
    parser.add_argument("--no-browser", action="store_true", help="print the URL without opening a browser")
    add_body_options(parser)
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from ..app import App, serve
    from ..dressing import check_strokes, read_strokes
    from ..errors import InputError
    from ..pattern import default_kimono, load_pattern
    from ._common import body_from_args  # noqa: PLC0415

    if not 0 <= args.port <= 65535:
        raise InputError(f"--port must be in 0..65535, got {args.port}")
    pattern = load_pattern(args.pattern) if args.pattern else default_kimono()
    strokes = None
    if args.strokes:
        strokes = read_strokes(args.strokes)
        check_strokes(strokes, pattern)
    body = body_from_args(args)
    serve(App(body, pattern, strokes), args.host, args.port, open_browser=not args.no_browser)
    return 0
