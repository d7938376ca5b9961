"""`kitsuke kimono simulate|calibrate`: the kimono simulated on the default body moved by poses, and the kimono's
posture limits E calibrated by simulation."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from ..errors import InputError
from ._common import checked_output
from .pose import add_frame_options, load_poses_from_args

SIMULATE_EPILOG = """\
The poses (anything `kitsuke pose extract` reads: a BVH file, a video, images, a poses JSON) move the default
body; the kimono, dressed on the body at rest (or given with --garment), is simulated on it frame by frame (XPBD
cloth: it stretches at most 2 %, collides with the moving body, its waist held in the obi). First the legs are
corrected for a kimono as `kitsuke pose correct` does (--no-correct to keep them raw: the kimono then tears or is
pierced where they stride wider than its hem); the clip is moved to start where the kimono was dressed, after a
short lead-in from the rest pose (--hold, --blend).

Writes an animated GLB (the skinned body and the kimono as one morph target per frame: Blender and three.js play
both), optionally an H.264 render (--video), a strip of six frames (--png) and a JSON report (--report) with, per
frame, the vertices more than 5 mm inside the body, the largest edge strain against the pattern and the time a
step took. A summary goes to stdout; frames that miss the targets (inside > 5 mm, strain > 10 %) are said on
stderr. A simulation that diverges exits 1 naming the frame, and writes nothing.

examples:
  kitsuke kimono simulate --poses tests/data/pose/cmu_131_01_start_walk_stop.bvh --stride 4 --max-frames 60 \\
                          -o walk_kimono.glb --video walk_kimono.mp4 --report walk_kimono.json
  kitsuke kimono simulate --poses clip.mp4 --stride 2 -o clip_kimono.glb
  kitsuke kimono simulate --poses walk.bvh --pattern kimono.json -o kimono.glb     # a kimono of your sizes
  kitsuke kimono simulate --poses walk.bvh --garment out/dressed.obj -o kimono.glb # one dressed before
"""


CALIBRATE_EPILOG = """\
For each joint pair (knees, ankles) and each angle θ of the line between the two joints (every --step degrees
from the left-to-right hip axis; 90° = the right leg forward), the default body, standing in the dressed kimono,
spreads its straight legs apart along θ, a little more each frame, with the kimono simulated. The widest spread
before the kimono breaks is E(θ), bisected from the first spread that broke. It breaks when the cloth below the obi
tears (1 % more of its edges stretched over 10 % than standing), a leg shows through it at the joint's height
(over 5 % of that band of the leg uncovered; an ankle below the hem is judged 8 cm above the hem), or cloth is
pushed 5 mm into the skin (0.5 % more of it than standing). A is the kimono's cross-section area at the joints'
height. The table (-o) is what `kitsuke pose correct --constraints` reads; the table shipped as "calibrated", the
correction's default, was made by the first example.

examples:
  kitsuke kimono calibrate -o kimono_standard_calibrated.json --plot e.png
  kitsuke pattern kimono --shoulder 34 --bolt-width 42 -o wide.json        # wider panels and okumi
  kitsuke kimono calibrate --pattern wide.json -o wide_constraints.json --plot wide.png
  kitsuke pose correct walk.bvh -o walk_corrected.json --constraints wide_constraints.json
"""


def register(parser: argparse.ArgumentParser) -> None:
    sub = parser.add_subparsers(dest="verb", metavar="<verb>")
    p = sub.add_parser(
        "simulate",
        help="simulate the kimono on the default body moved by poses: animated GLB, video, report",
        description="Dress the kimono on the default body and simulate it over a pose sequence.",
        epilog=SIMULATE_EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument(
        "--poses", dest="source", required=True, metavar="POSES", help="BVH, video, image folder or poses JSON"
    )
    p.set_defaults(camera=None)
    p.add_argument("-o", "--output", required=True, help="output animated GLB (body and kimono)")
    k = p.add_argument_group("the kimono (default: the default kimono, dressed now)")
    k.add_argument("--pattern", metavar="K.json", help="a kimono pattern (`kitsuke pattern kimono`) to dress")
    k.add_argument("--garment", metavar="DRESSED.obj", help="a kimono already dressed on the default body (its OBJ)")
    s = p.add_argument_group("simulation")
    s.add_argument("--no-correct", dest="correct", action="store_false", help="keep the legs as the poses give them")
    s.add_argument("--constraints", metavar="TABLE.json", help="E/A table for the leg correction (default: shipped)")
    s.add_argument("--hold", type=float, default=0.2, metavar="S", help="seconds at rest first (default 0.2)")
    s.add_argument("--blend", type=float, default=0.5, metavar="S", help="seconds to blend into frame 1 (default 0.5)")
    s.add_argument("--substeps", type=int, default=20, metavar="N", help="solver substeps per frame (default 20)")
    o = p.add_argument_group("more outputs")
    o.add_argument("--video", metavar="MP4", help="an H.264 render of the kimono on the moving body")
    o.add_argument("--png", metavar="PNG", help="six frames of the clip side by side")
    o.add_argument("--report", metavar="JSON", help="summary and per-frame measures")
    add_frame_options(p)
    p.set_defaults(run=run_simulate)

    p = sub.add_parser(
        "calibrate",
        help="the kimono's posture limits E(θ) and areas A for knees and ankles, by cloth simulation",
        description="Calibrate the constraint table of a kimono on the default body by simulating leg spreads.",
        epilog=CALIBRATE_EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("-o", "--output", required=True, help="output constraints table (.json)")
    k = p.add_argument_group("the kimono (default: the default kimono, dressed now)")
    k.add_argument("--pattern", metavar="K.json", help="a kimono pattern (`kitsuke pattern kimono`) to dress")
    k.add_argument("--garment", metavar="DRESSED.obj", help="a kimono already dressed on the default body (its OBJ)")
    p.add_argument("--plot", metavar="PNG", help="a polar plot of E(θ) against the geometric estimate")
    p.add_argument("--step", type=float, default=15.0, metavar="DEG", help="angle step, divides 180 (default 15)")
    p.add_argument("--workers", type=int, default=2, metavar="N", help="processes in parallel (default 2)")
    p.set_defaults(run=run_calibrate)


def _garment(args: argparse.Namespace, body):  # noqa: ANN001, ANN202

    if args.pattern and args.garment:
        raise InputError("give --pattern or --garment, not both")
    if args.garment:
        from ..dressing.export import read_garment_obj

        return read_garment_obj(args.garment)
    from ..tryon import default_simulation_kimono

    pattern = None
    if args.pattern:
        from ..dressing.kimono import check_kimono
        from ..pattern import load_pattern

        pattern = load_pattern(args.pattern)
        check_kimono(pattern)
    print("dressing the kimono on the default body ...", file=sys.stderr)
    return default_simulation_kimono(body, pattern)


def run_simulate(args: argparse.Namespace) -> int:
    from dataclasses import replace

    from ..body import default_body
    from ..pose import read_constraints
    from ..tryon import SimulationSettings, check_poses, simulate_kimono
    from ..tryon.outputs import picture_strip, write_kimono_glb, write_kimono_video, write_motion_report

    inputs = [a for a in (args.source, args.pattern, args.garment, args.constraints) if a]
    outs = [checked_output(args.output, inputs, suffixes=(".glb",))]
    for extra, suffix in ((args.video, ".mp4"), (args.png, ".png"), (args.report, ".json")):
        if extra:
            outs.append(checked_output(extra, inputs, suffixes=(suffix,)))
    if len({o.resolve() for o in outs}) != len(outs):
        raise InputError("the output files must be different")
    if not Path(args.source).exists():
        raise InputError("not found", args.source)
    settings = SimulationSettings(correct=args.correct, hold_s=args.hold, blend_s=args.blend)
    settings = replace(settings, dynamics=replace(settings.dynamics, substeps=args.substeps))
    table = read_constraints(args.constraints) if args.constraints else None
    poses = load_poses_from_args(args)
    check_poses(poses)
    body = default_body()
    garment = _garment(args, body)
    motion = simulate_kimono(poses, body=body, garment=garment, constraints=table, settings=settings)
    write_kimono_glb(motion, body, outs[0])
    if args.video:
        write_kimono_video(motion, body, args.video)
    if args.png:
        from ..render import write_png

        write_png(args.png, picture_strip(motion, body))
    summary = motion.summary()
    per_frame = summary.pop("per_frame")
    if args.report:
        write_motion_report(motion, args.report, poses=str(args.source), output=str(outs[0]))
    print(json.dumps({"output": str(outs[0]), **summary}, indent=1))
    missed = [q for q in per_frame if not q["ok"] and not q["lead_in"]]
    if missed:
        w = summary["worst"]
        print(
            f"warning: {len(missed)} of {summary['clip_frames']} frames miss the targets (worst: strain "
            f"{100 * w['strain_max']:.0f} % where 10 % is the target, {w['penetration_count']} vertices more than "
            f"5 mm inside, deepest {w['penetration_deepest_mm']:.0f} mm)",
            file=sys.stderr,
        )
    return 0


def run_calibrate(args: argparse.Namespace) -> int:
    from ..body import default_body
    from ..pose import packaged_constraints, write_constraints
    from ..tryon.calibrate import CalibrationSettings, calibrate, plot_constraints

    inputs = [a for a in (args.pattern, args.garment) if a]
    out = checked_output(args.output, inputs, suffixes=(".json",))
    plot = checked_output(args.plot, inputs, suffixes=(".png",)) if args.plot else None
    if plot is not None and plot.resolve() == out.resolve():
        raise InputError("the output files must be different")
    settings = CalibrationSettings(theta_step_deg=args.step, workers=args.workers)
    body = default_body()
    garment = _garment(args, body)
    label = f"kimono {Path(args.pattern or args.garment).stem}" if args.pattern or args.garment else "kimono standard"
    result = calibrate(garment, body, settings=settings, label=label)
    write_constraints(result.table, out)
    if plot is not None:
        plot_constraints(result.table, plot, against=packaged_constraints("geometric"), title=label)
    summary = {
        "output": str(out),
        "seconds": round(result.seconds, 1),
        **{
            pair: {
                "area_m2": round(result.table.pair(pair).area_m2, 4),
                "theta_deg": [r["theta_deg"] for r in spreads],
                "max_distance_m": [round(r["max_distance_m"], 3) for r in spreads],
                "broke_by": [r["broke"] for r in spreads],
            }
            for pair, spreads in result.spreads.items()
        },
    }
    print(json.dumps(summary, indent=1))
    return 0
