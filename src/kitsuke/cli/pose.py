"""`kitsuke pose extract|correct|animate`: poses from video/images/camera/BVH, kimono posture correction, and the
default body animated by them."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from ._common import checked_output

EXTRACT_EPILOG = """\
SOURCE is a video file, an image, a folder of images (sorted by name), a BVH file or a kitsuke poses JSON file;
use --camera N instead of SOURCE for a live camera (Ctrl-C stops it). Poses are written in the SPEC joint set
(23 joints), metres, Y up, the person facing +Z; video and image sources keep each joint's pixel position.

examples:
  kitsuke pose extract clip.mp4 -o poses.json
  kitsuke pose extract clip.mp4 -o poses.json --stride 2 --max-frames 300 --no-filter
  kitsuke pose extract walk.bvh -o walk.json          # CMU, MakeHuman, DAZ, Mixamo names
  kitsuke pose extract --camera 0 -o live.json --seconds 10
"""

CORRECT_EPILOG = """\
Each frame's knees and then ankles are checked against the kimono's limit E(θ) (SPEC 5.3); where the legs are
too far apart, the thigh (or shin) of the leg farther from the pelvis is rotated into the region allowed by the
previous frame, keeping bone lengths and the motion's continuity. A JSON summary of the SPEC 6 measures
(fraction of frames corrected, residual, largest jumps raw vs corrected, invariant checks) goes to stdout.

examples:
  kitsuke pose correct clip.mp4 -o corrected.json --plot legs.png --video overlay.mp4
  kitsuke pose correct poses.json -o corrected.json --constraints my_kimono.json
  kitsuke pose correct poses.json -o corrected.json --constraints calibrated  # the shipped simulated table
  kitsuke pose correct kick.bvh -o kick_corrected.json --video kick.mp4
"""


ANIMATE_EPILOG = """\
The default body (MakeHuman's, rigged to the SPEC joint set) is posed at every frame: each bone turns to point along
the observed one, keeping the body's own bone lengths; hips and shoulders twist so that knees and elbows bend about
their hinges, and the pelvis follows the observed one (the clip is moved once so the feet stand on the floor).
The GLB holds the skinned body and one animation ("motion"), as Blender, three.js and other glTF viewers play it.
A JSON summary goes to stdout: frames, duration, and the skin's quality at the hips, knees, elbows and shoulders
(shortest and longest edge against rest, most faces turned inside out in a frame).

examples:
  kitsuke pose animate walk.bvh -o walk.glb
  kitsuke pose animate clip.mp4 -o clip.glb --stride 2
  kitsuke pose animate corrected.json -o kimono_legs.glb     # the output of `pose correct`
"""


def _add_source_options(
    p: argparse.ArgumentParser, output_help: str = "output poses JSON file (kitsuke.poses v1)"
) -> None:
    p.add_argument("source", nargs="?", help="video, image, image folder, .bvh or poses .json file")
    p.add_argument("--camera", type=int, metavar="N", help="read a live camera with this index instead of SOURCE")
    p.add_argument("-o", "--output", required=True, help=output_help)
    add_frame_options(p)


def add_frame_options(p: argparse.ArgumentParser) -> None:
    """Which frames of a pose source to read, and its temporal filter (`load_poses_from_args` reads them)."""
    g = p.add_argument_group("frames")
    g.add_argument("--stride", type=int, default=1, metavar="K", help="use every K-th frame (video, BVH); default 1")
    g.add_argument("--max-frames", type=int, metavar="N", help="stop after N frames (default: all)")
    g.add_argument("--start", type=float, default=0.0, metavar="S", help="skip the first S seconds of a video")
    g.add_argument("--fps", type=float, default=30.0, help="frame rate given to a folder of images (default 30)")
    g.add_argument("--seconds", type=float, metavar="S", help="stop a camera after S seconds (default: Ctrl-C)")
    g.add_argument(
        "--bvh-scale", type=float, metavar="M", help="metres per BVH unit (default: chosen from the skeleton's height)"
    )
    f = p.add_argument_group("temporal filter (One-Euro)")
    f.add_argument(
        "--filter",
        dest="filter",
        action="store_true",
        default=None,
        help="filter the positions (default: on for video and camera, off for BVH, JSON and images)",
    )
    f.add_argument("--no-filter", dest="filter", action="store_false", help="do not filter")
    f.add_argument(
        "--min-cutoff",
        type=float,
        default=1.0,
        metavar="HZ",
        help="cut-off frequency when still, Hz (lower = smoother); default 1.0",
    )
    f.add_argument(
        "--beta", type=float, default=2.0, help="cut-off increase per m/s of speed (higher = less lag); default 2.0"
    )
    f.add_argument(
        "--d-cutoff", type=float, default=1.0, metavar="HZ", help="cut-off of the speed estimate, Hz; default 1.0"
    )


def register(parser: argparse.ArgumentParser) -> None:
    sub = parser.add_subparsers(dest="verb", metavar="<verb>")
    p = sub.add_parser(
        "extract",
        help="poses from a video, images, a camera or a BVH file",
        description="Extract poses (MediaPipe for pixels, naming rules for BVH) into a kitsuke poses JSON file.",
        epilog=EXTRACT_EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    _add_source_options(p)
    p.set_defaults(run=run_extract)

    p = sub.add_parser(
        "correct",
        help="correct poses for a kimono (knees, then ankles) and report the measures",
        description="Kimono posture correction (SPEC 5.3) of a pose source or a poses JSON file.",
        epilog=CORRECT_EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    _add_source_options(p)
    p.add_argument(
        "--constraints",
        metavar="TABLE.json",
        help="E/A table (SPEC 3.4 constraints) file, or a shipped one by name: calibrated (the default, by "
        "cloth simulation) or geometric (a geometric estimate)",
    )
    p.add_argument("--plot", metavar="PNG", help="write a plot of knee/ankle distances, raw and corrected, vs E(θ)")
    p.add_argument(
        "--video",
        metavar="MP4",
        help="write an H.264 overlay video: raw skeleton grey, corrected in colour (rotated parts red)",
    )
    p.add_argument(
        "--side-by-side",
        action="store_true",
        help="with --video: the raw skeleton on the left copy of each frame, the corrected one on the right",
    )
    p.add_argument("--summary", metavar="JSON", help="also write the summary to this file")
    p.set_defaults(run=run_correct)

    p = sub.add_parser(
        "animate",
        help="the default body animated by a pose source: an animated, skinned GLB",
        description="Pose the default body at every frame of a pose source and write it as an animated GLB.",
        epilog=ANIMATE_EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    _add_source_options(p, output_help="output animated GLB (.glb)")
    p.set_defaults(run=run_animate)


def load_poses_from_args(args: argparse.Namespace):  # noqa: ANN201 - PoseSequence, imported lazily
    """The poses named by args.source or args.camera, with the options of `add_frame_options`."""
    from ..errors import InputError
    from ..pose import OneEuroConfig, load_poses

    if (args.source is None) == (args.camera is None):
        raise InputError("give either SOURCE or --camera N (see --help)")
    if args.stride < 1:
        raise InputError(f"--stride must be at least 1, got {args.stride}")
    if args.max_frames is not None and args.max_frames < 1:
        raise InputError(f"--max-frames must be at least 1, got {args.max_frames}")
    source = args.camera if args.camera is not None else args.source
    if args.camera is None and not Path(source).exists():
        raise InputError("not found", source)
    flt = args.filter
    if flt is not False:
        try:
            cfg = OneEuroConfig(min_cutoff_hz=args.min_cutoff, beta=args.beta, d_cutoff_hz=args.d_cutoff)
        except ValueError as e:
            raise InputError(str(e)) from None
        flt = cfg if flt else None
        if flt is None:
            from ..pose import source_kind

            flt = cfg if source_kind(source) in ("video", "camera") else False
    return load_poses(
        source,
        filter=flt,
        stride=args.stride,
        max_frames=args.max_frames,
        start_s=args.start,
        fps=args.fps,
        scale=args.bvh_scale,
        seconds=args.seconds,
    )


def _inputs(args: argparse.Namespace) -> list[str]:
    from ..pose._constraints import PACKAGED_CONSTRAINTS

    named = getattr(args, "constraints", None) in PACKAGED_CONSTRAINTS
    return [a for a in (args.source, None if named else getattr(args, "constraints", None)) if a]


def _warn_if_nobody(poses) -> None:  # noqa: ANN001 - PoseSequence, imported lazily
    if poses.n_frames and not poses.valid.any():
        what = "the image" if poses.n_frames == 1 else f"any of the {poses.n_frames} frames"
        print(f"warning: no person found in {what}", file=sys.stderr)


def run_extract(args: argparse.Namespace) -> int:
    from ..pose import write_poses

    out = checked_output(args.output, _inputs(args))
    poses = load_poses_from_args(args)
    write_poses(poses, out)
    n_valid = int(poses.valid.sum())
    print(f"wrote {out}: {poses.n_frames} frames ({n_valid} with a person) at {poses.fps:g} fps", file=sys.stderr)
    _warn_if_nobody(poses)
    if poses.source.get("truncated"):
        print(
            f"warning: the video ended after {poses.source['frames_decoded']} of {poses.source['frames']} frames "
            "(truncated file?)",
            file=sys.stderr,
        )
    return 0


def run_correct(args: argparse.Namespace) -> int:
    from .._files import write_json_atomic
    from ..errors import InputError
    from ..pose import (
        correct_poses,
        correction_measures,
        load_constraints,
        plot_distances,
        write_overlay_video,
        write_poses,
    )

    inputs = _inputs(args)
    out = checked_output(args.output, inputs)
    outs = [out]
    for extra, suffix in ((args.plot, ".png"), (args.video, ".mp4"), (args.summary, ".json")):
        if extra:
            if Path(extra).suffix.lower() != suffix:
                raise InputError(f"must be a {suffix} file", extra)
            outs.append(checked_output(extra, inputs))
    if len({p.resolve() for p in outs}) != len(outs):
        raise InputError("the output files must be different")
    table = load_constraints(args.constraints) if args.constraints else None
    poses = load_poses_from_args(args)
    correction = correct_poses(poses, table)
    measures = correction_measures(correction)
    write_poses(correction.poses, out)
    base = Path(args.source).parent if args.source else None
    if args.plot:
        plot_distances(correction, args.plot, title=str(args.source if args.source else f"camera {args.camera}"))
    summary = {"output": str(out), **measures}
    if args.video:
        summary["overlay"] = write_overlay_video(correction, args.video, base_dir=base, side_by_side=args.side_by_side)
    _warn_if_nobody(poses)
    if args.summary:
        write_json_atomic(args.summary, summary)
    print(json.dumps(summary, indent=1))
    return 0


def run_animate(args: argparse.Namespace) -> int:
    import numpy as np

    from ..body import default_body
    from ..body.animate import animate, skinning_quality
    from ..body.gltf_animation import write_animated_glb

    out = checked_output(args.output, _inputs(args), suffixes=(".glb",))
    poses = load_poses_from_args(args)
    _warn_if_nobody(poses)
    body = default_body()
    animation = animate(body, poses)
    write_animated_glb(body, animation, out)
    frames = np.arange(0, animation.n_frames, max(1, animation.n_frames // 100))  # the skin checked on 100 frames
    quality = skinning_quality(body, animation, frames)
    summary = {
        "output": str(out),
        "frames": animation.n_frames,
        "frames_posed": int(animation.valid.sum()),
        "duration_s": round(float(animation.times[-1] - animation.times[0]), 4),
        "fps": animation.fps,
        "skin_checked_frames": len(frames),
        "skin": {k: {n: x if isinstance(x, int) else round(x, 4) for n, x in v.items()} for k, v in quality.items()},
    }
    print(json.dumps(summary, indent=1))
    return 0
