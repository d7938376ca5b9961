"""`kitsuke drag`: replay a drags file (SPEC §3.5) on a dressed garment: pins, grabs, moves along the body."""

from __future__ import annotations

import argparse
import sys

from ._common import add_body_options, body_from_args, checked_output

EPILOG = """\
BODY is a mesh file (OBJ, GLB, PLY; units and axes detected) or `default` (the built-in MakeHuman body): the body
the garment was dressed on. GARMENT is a dressed-garment OBJ as `kitsuke dress --obj` writes it (v = world metres,
vt = pattern metres: the rest shape). DRAGS is a kitsuke drags JSON (SPEC 3.5): steps, each optionally unpinning
("unpin": "all" or points), pinning ("pins": points, snapped to the nearest garment vertex), grabbing the garment
at a point ("grab") and moving the grab through "path" points (each projected onto the body); the whole garment
follows along the body, attenuated towards the pins and not past them. All points in metres, Y up.

Outputs: OUT.obj, the dragged garment in the same OBJ layout (so it can be dragged again; a release may refine
it where the drag bunched the cloth: more vertices, the old ones keep their indices); --report a JSON with the
quality before and after (penetration, strain, seam gap, inverted triangles), what each step did (pins, the grab,
its updates and timings, and its release: the polish, new vertices, how far the let-go point gave back where the
cloth was too taut to stay) and the update timings; --png a front/side/back picture. Nothing is written if any
step fails (e.g. a grab off the garment, a path point off the body, every vertex pinned): the error names the
drags file and the step.

examples:
  kitsuke dress --body default --pattern kimono.json --strokes kimono_default.json -o k.glb --obj kimono.obj
  kitsuke drag --body default --garment kimono.obj --drags lift.json -o lifted.obj --report lifted.json --png l.png
"""


def register(parser: argparse.ArgumentParser) -> None:
    parser.description = (
        "Drag a dressed garment along the body as a drags file says: pin points, grab the garment, move the grab; "
        "the garment follows along the body surface."
    )
    parser.epilog = EPILOG
    parser.formatter_class = argparse.RawDescriptionHelpFormatter
    parser.add_argument("--body", required=True, metavar="BODY", help="body mesh file or `default`")
    parser.add_argument("--garment", required=True, metavar="GARMENT.obj", help="dressed garment OBJ (kitsuke dress)")
    parser.add_argument("--drags", required=True, metavar="DRAGS.json", help="kitsuke drags JSON (SPEC 3.5)")
    parser.add_argument("-o", "--output", required=True, metavar="OUT.obj", help="the dragged garment, OBJ")
    parser.add_argument("--report", metavar="REPORT.json", help="also write quality before/after, steps, timings")
    parser.add_argument("--png", metavar="VIEWS.png", help="also write a front/side/back picture")
    parser.add_argument(
        "--step",
        type=float,
        default=1.0,
        metavar="CM",
        help="longest move of the grab per update, cm: longer moves are split (default 1)",
    )
    add_body_options(parser)
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    import time

    from .._files import write_json_atomic
    from ..cloth import precompile_in_background
    from ..dressing.drag import DragParams, DragSession
    from ..dressing.drags import apply_drags, read_drags
    from ..dressing.export import read_garment_obj, write_garment_obj, write_garment_png
    from ..errors import InputError

    inputs = [args.body, args.garment, args.drags]
    outs = [checked_output(args.output, inputs, suffixes=(".obj",))]
    for extra, suffix in ((args.report, ".json"), (args.png, ".png")):
        if extra:
            outs.append(checked_output(extra, inputs, suffixes=(suffix,)))
    if len({o.resolve() for o in outs}) != len(outs):
        raise InputError("the output files must be different")
    if not 0.05 <= args.step <= 20:
        raise InputError(f"--step must be between 0.05 and 20 cm, got {args.step}")
    # Cheap checks first: bad drags or garment files fail before the body is loaded.
    drags = read_drags(args.drags)
    garment = read_garment_obj(args.garment)
    precompile_in_background()  # the first run after an install: compile the release's polish on the other core
    body = body_from_args(args)
    t0 = time.perf_counter()
    session = DragSession(body, garment, params=DragParams(max_step_m=args.step / 100), source=args.garment)
    before = session.report()
    t1 = time.perf_counter()
    steps = apply_drags(session, drags)
    t2 = time.perf_counter()
    after = session.report()
    dragged = session.garment()
    write_garment_obj(dragged, args.output)
    if args.report:
        ups = [t for s in steps for m in s.moves for t in m.update_seconds]
        write_json_atomic(
            args.report,
            {
                "garment": dragged.name,
                "vertices": session.n_vertices,
                "faces": int(session.model.n_faces),
                "drags": str(args.drags),
                "steps": [s.to_dict() for s in steps],
                "timings_s": {"prepare": round(t1 - t0, 4), "drags": round(t2 - t1, 4)},
                "updates": len(ups),
                "update_ms_median": round(1e3 * sorted(ups)[len(ups) // 2], 3) if ups else None,
                "quality_before": before.to_dict(),
                "quality_after": after.to_dict(),
            },
        )
    if args.png:
        write_garment_png(dragged, body.mesh, args.png)
    verdict = "all quality targets met" if after.ok else "targets missed: " + ", ".join(after.failures())
    print(
        f"wrote {args.output}: {len(drags)} steps, {sum(len(s.moves) for s in steps)} path points, "
        f"{t2 - t1:.2f} s; {verdict}",
        file=sys.stderr,
    )
    return 0
