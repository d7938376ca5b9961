"""`kitsuke batch dress|calibrate`: many dress jobs, or kimono calibrations, from a manifest, on this machine's
cores or a Ray cluster."""

from __future__ import annotations

import argparse
import sys

DRESS_EPILOG = """\
MANIFEST is CSV or JSON, one job per row: id, body, pattern and strokes required, the rest optional (an empty
cell takes the default). Relative paths are from the manifest's folder. For example:

  id,body,pattern,strokes,edge_length
  shirt,mean_all.obj,shirt_mean_specification.json,shirt_mean_all.json,
  skirt,mean_all.obj,corpus/gc_s101_0003_specification.json,suggest,2.5

or in JSON: {"defaults": {"body": "mean_all.obj"}, "jobs": [{"id": "shirt", "pattern": "...", "strokes": "..."}]}

manifest columns:
{columns}

Each job writes OUTDIR/ID/: garment.obj, report.json, garment.glb (garment and body), strokes.json when suggested,
views.png when asked, and result.json (its status, reason, measures, time). OUTDIR/summary.csv and summary.json
list every job: id, status (ok, out_of_target, refused, failed; not_run if the batch was stopped first), reason,
seconds, the quality measures (strain mean / max %, deepest mm inside, seam gap mm, inverted, stroke residual mm)
and the worker. A job that is refused, fails, runs past its time limit or kills its worker is recorded with its
reason and the batch goes on. Exit 0 when every job gave a garment, 1 when some did not (see the summary), 2
for a manifest that is not one (nothing runs, nothing is written).

A job's folder appears complete or not at all. --resume runs only the jobs without one (after a crash, Ctrl-C or
kill); without it, OUTDIR must be new or empty.

Runs on Ray (pip install 'kitsuke[batch]'): without --address a local Ray is started for the batch with a worker
per core; with --address it joins a running cluster (`ray start --head` on one machine prints the address,
`ray start --address ADDR` on each other one; every machine needs kitsuke installed). Inputs are read here and
sent to the workers, outputs come back here: the workers need no shared disk. --local runs the same jobs in a
process pool on this machine, without Ray.

examples:
  kitsuke batch dress jobs.csv -o out/                   # local Ray, a worker per core
  kitsuke batch dress jobs.csv -o out/ --local --workers 2
  kitsuke batch dress jobs.csv -o out/ --resume          # finish what a stopped batch left
  kitsuke batch dress jobs.json -o out/ --address 10.0.0.5:6379 --timeout 1800
"""


CALIBRATE_EPILOG = """\
MANIFEST is CSV or JSON, one kimono per row (id and pattern required), as for `kitsuke batch dress`:

  id,pattern,step
  standard,default,15
  wide,wide_kimono.json,15

manifest columns:
{columns}

Each job runs `kitsuke kimono calibrate` on the default body: the kimono dressed for simulation, then its limits
E(θ) for the knees and the ankles by simulated leg spreads, one after another (about 2-4 minutes a kimono on one
core; the batch's workers run kimonos side by side). It writes OUTDIR/ID/constraints.json (what `kitsuke pose
correct --constraints` reads) and e.png (E against the geometric estimate), and result.json. The summary lists each
kimono's smallest and largest E (cm) and cross-section area A (cm²) for knees and ankles. Time limit, resume,
failure isolation and Ray (--address, --local) as for `kitsuke batch dress`.

examples:
  kitsuke batch calibrate kimonos.csv -o limits/ --local --workers 2
  kitsuke batch calibrate kimonos.csv -o limits/ --address 10.0.0.5:6379
"""


def register(parser: argparse.ArgumentParser) -> None:
    verbs = parser.add_subparsers(dest="verb", metavar="<verb>")
    p = verbs.add_parser(
        "dress",
        help="dress many garments on many bodies (one `kitsuke dress` per manifest row)",
        description="Dress many garments on many bodies: one `kitsuke dress` per manifest row, in parallel.",
        epilog=DRESS_EPILOG.replace("{columns}", _columns()),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    _add_batch_options(p)
    p.set_defaults(run=run_dress)
    p = verbs.add_parser(
        "calibrate",
        help="calibrate many kimonos' posture limits E (one `kitsuke kimono calibrate` per manifest row)",
        description="Calibrate the posture limits E of many kimonos: one `kitsuke kimono calibrate` per row.",
        epilog=CALIBRATE_EPILOG.replace("{columns}", _columns(calibrate=True)),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    _add_batch_options(p, timeout_s=1800.0)
    p.set_defaults(run=run_calibrate)


def _add_batch_options(p: argparse.ArgumentParser, timeout_s: float = 600.0) -> None:
    p.add_argument("manifest", metavar="MANIFEST", help="CSV or JSON manifest, one job per row")
    p.add_argument("-o", "--output", required=True, metavar="OUTDIR", help="output folder (new, empty, or --resume)")
    p.add_argument("--resume", action="store_true", help="run only the jobs OUTDIR has no finished folder for")
    p.add_argument("--retry-failed", action="store_true", help="with --resume: also run the failed jobs again")
    p.add_argument("--workers", type=int, metavar="N", help="workers (default: one per core of the machine or cluster)")
    p.add_argument(
        "--timeout",
        type=float,
        default=timeout_s,
        metavar="S",
        help=f"seconds a job may run before its worker is stopped and it is recorded as failed (default "
        f"{timeout_s:g}; a manifest's timeout column overrides it per job)",
    )
    where = p.add_mutually_exclusive_group()
    where.add_argument("--address", metavar="ADDR", help="join this Ray cluster (host:port, or `auto`)")
    where.add_argument("--local", action="store_true", help="run in a process pool on this machine, without Ray")


def _columns(calibrate: bool = False) -> str:
    from ..batch.manifest import CALIBRATE_COLUMNS, COLUMNS

    return "\n".join(f"  {name:13s} {what}" for name, what in (CALIBRATE_COLUMNS if calibrate else COLUMNS).items())


def run_dress(args: argparse.Namespace) -> int:
    from ..batch import DressKind, read_manifest

    return _run(args, DressKind(), read_manifest, "gave no garment")


def run_calibrate(args: argparse.Namespace) -> int:
    from ..batch import CalibrateKind, read_calibrate_manifest

    return _run(args, CalibrateKind(), read_calibrate_manifest, "gave no table")


def _run(args: argparse.Namespace, kind, read, failed_words: str) -> int:  # noqa: ANN001
    from ..batch import LocalRunner, RayRunner, ray_available, run_batch
    from ..errors import ComputationError, InputError

    if args.retry_failed and not args.resume:
        raise InputError("--retry-failed goes with --resume (it runs a finished batch's failed jobs again)")
    if not args.local and not ray_available():
        raise InputError(
            "Ray is not installed: pip install 'kitsuke[batch]' to run batches on Ray, or add --local to run this one "
            "in a process pool on this machine"
        )
    jobs = read(args.manifest)
    if args.local:
        runner = LocalRunner(workers=args.workers, timeout_s=args.timeout)
    else:
        runner = RayRunner(address=args.address, workers=args.workers, timeout_s=args.timeout)
    result = run_batch(kind, jobs, args.output, runner, resume=args.resume, retry_failed=args.retry_failed)
    c = result.counts
    print(
        f"{len(jobs)} jobs: {c['ok']} ok, {c['out_of_target']} out of target, {c['refused']} refused, "
        f"{c['failed']} failed; ran {result.ran} in {result.seconds:.0f} s"
        + (f", {result.skipped} finished before" if result.skipped else "")
        + f"; wrote {result.summary_csv}",
        file=sys.stderr,
    )
    if result.unfinished:
        raise ComputationError(
            "batch", f"{result.unfinished} of {len(jobs)} jobs {failed_words}: see {result.summary_csv}"
        )
    return 0
