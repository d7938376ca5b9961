"""`kitsuke tryon`: the try-on mirror on a video, an image folder or a camera."""

from __future__ import annotations

import argparse
import json
import sys

from ..errors import InputError
from ._common import checked_output

EPILOG = """\
Per frame: the person's pose (MediaPipe, the bundled model; the largest person when there are several),
filtered; the legs corrected as a kimono holds them (the paper's posture correction; --no-correct to keep them);
the default body posed; one step of the kimono's cloth simulation; a camera fitted to the person (its focal length
over the first frames, its pose every frame); the kimono drawn over the frame, with the body hiding its inside and
back. Where the correction moved a leg, the kimono follows the corrected leg and the person's own leg may show
outside it: that is the paper's feedback, shown as it is. Frames are scaled to fit 640x480 (portrait: 480x640).
Frames without a person keep the kimono where it was and fade it out over a second.

Writes an H.264 mp4 (-o), or opens a mirror window (--window: flipped like a mirror, with the frame rate; keys
q quit, c correction on/off, s snapshot PNG). --compare writes the uncorrected try-on beside the corrected one.
The report (--report) has, per frame, the registration residual (px), the kimono's largest strain and the time
of each stage; its summary goes to stdout, and what missed a target (registration over 10 px mean at 640x480)
goes to stderr.

examples:
  kitsuke tryon tests/data/pose/tfjs_pose_squats.mp4 -o squats_kimono.mp4 --report squats.json
  kitsuke tryon clip.mp4 -o compare.mp4 --compare --plot legs.png     # before / after the correction
  kitsuke tryon frames/ --fps 25 -o out.mp4                            # a folder of images
  kitsuke tryon --camera 0 --window                                    # the live mirror
"""


def register(parser: argparse.ArgumentParser) -> None:
    parser.description = "The kimono try-on mirror: a person on video or camera, wearing a simulated kimono."
    parser.epilog = EPILOG
    parser.formatter_class = argparse.RawDescriptionHelpFormatter
    parser.add_argument("source", nargs="?", metavar="SOURCE", help="a video file or a folder of images")
    parser.add_argument("--camera", type=int, metavar="N", help="camera N instead of a file (0: the first)")
    parser.add_argument("-o", "--output", metavar="OUT.mp4", help="the try-on as an H.264 mp4")
    parser.add_argument("--window", action="store_true", help="open the live mirror window instead of writing")
    parser.add_argument("--report", metavar="R.json", help="summary and per-frame measures")
    parser.add_argument("--compare", action="store_true", help="uncorrected | corrected, side by side, in -o")
    parser.add_argument("--plot", metavar="LEGS.png", help="knee and ankle distances, raw and corrected, vs E(θ)")
    parser.add_argument(
        "--constraints",
        metavar="TABLE",
        help="E/A table for the correction: a file, or `calibrated` (the default, by cloth simulation) / `geometric`",
    )
    parser.add_argument("--no-correct", dest="correct", action="store_false", help="keep the legs as detected")
    parser.add_argument("--fps", type=float, metavar="F", help="frame rate of an image folder (default 30)")
    parser.add_argument(
        "--edge-cm",
        type=float,
        metavar="CM",
        help="the kimono's mesh edge length (default 2.5 for files, 4 in the window: faster, coarser folds)",
    )
    parser.add_argument("--max-frames", type=int, metavar="N", help="stop after N frames")
    parser.add_argument("--snapshots", default=".", metavar="DIR", help="where `s` saves snapshots (default .)")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from ..pose import load_constraints
    from ..tryon import LIVE_EDGE_CM, SIMULATION_EDGE_CM, TryOnSettings

    if (args.source is None) == (args.camera is None):
        raise InputError("give a SOURCE (video or image folder) or --camera N, not both")
    if not args.window and args.output is None:
        raise InputError("give -o OUT.mp4 to write the try-on, or --window for the live mirror")
    if args.window and (args.output or args.compare):
        raise InputError("--window shows the mirror live; -o and --compare write files: run them separately")
    if args.fps is not None and not (0 < args.fps <= 1000):
        raise InputError(f"--fps must be in (0, 1000], got {args.fps}")
    if args.max_frames is not None and args.max_frames < 1:
        raise InputError(f"--max-frames must be at least 1, got {args.max_frames}")
    if args.edge_cm is not None and not (1.0 <= args.edge_cm <= 10.0):
        raise InputError(f"--edge-cm must be in [1, 10] cm, got {args.edge_cm}")
    source = args.camera if args.camera is not None else args.source
    inputs = [a for a in (args.source, args.constraints) if a]
    for out, suffix in ((args.output, ".mp4"), (args.report, ".json"), (args.plot, ".png")):
        if out:
            checked_output(out, inputs, suffixes=(suffix,))
    outs = [o for o in (args.output, args.report, args.plot) if o]
    if len(set(outs)) != len(outs):
        raise InputError("the output files must be different")
    table = load_constraints(args.constraints) if args.constraints else None
    edge = args.edge_cm or (LIVE_EDGE_CM if args.window else SIMULATION_EDGE_CM)
    settings = TryOnSettings(correct=args.correct, edge_cm=edge)
    if args.window:
        from ..tryon.live import Window, run_live

        window = Window()  # no display: said before any work
        print("dressing the kimono on the default body ...", file=sys.stderr)
        try:
            result = run_live(
                source, window, settings=settings, constraints=table, snapshots=args.snapshots,
                on_snapshot=lambda p: print(f"saved {p}", file=sys.stderr),
            )  # fmt: skip
        finally:
            window.close()
        if args.report:
            from .._files import write_json_atomic

            write_json_atomic(args.report, {**result.summary(), "warnings": result.warnings()})
    else:
        from ..tryon import run_tryon

        print("dressing the kimono on the default body ...", file=sys.stderr)
        result = run_tryon(
            source, args.output, report=args.report, compare=args.compare, plot=args.plot, settings=settings,
            constraints=table, fps=args.fps, max_frames=args.max_frames,
        )  # fmt: skip
    summary = result.summary()
    summary.pop("per_frame")
    print(json.dumps({"output": args.output, **summary}, indent=1))
    for line in result.warnings():
        print(f"warning: {line}", file=sys.stderr)
    return 0
