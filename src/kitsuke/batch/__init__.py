"""Batches: many dress jobs, or kimono calibrations, from a manifest, on this machine's cores or a Ray cluster
(`kitsuke batch dress`, `kitsuke batch calibrate`).

    from kitsuke.batch import DressKind, LocalRunner, RayRunner, read_manifest, run_batch
    jobs = read_manifest("jobs.csv")                         # InputError naming the file and row if it is not one
    result = run_batch(DressKind(), jobs, "out/", LocalRunner(workers=2, timeout_s=600))
    result.counts                                            # {"ok": 4, "out_of_target": 1, "refused": 1, ...}

- `manifest`: CSV / JSON manifests -> `Job`s (body, pattern, strokes or "suggest", options).
- `jobs`: `DressKind`, one dress job in a worker by the same library calls as `kitsuke dress`;
  `calibrate_jobs`: `CalibrateKind`, one kimono calibration as `kitsuke kimono calibrate` (`read_calibrate_manifest`).
- `runners`: the scheduler every runner shares: warm workers, shared inputs read once, per-job time limits,
  failures kept to their job; `workers`: what each worker does; `local`: `LocalRunner`, a process pool on this
  machine; `on_ray`: `RayRunner`, Ray actors, local or on a cluster.
- `outdir`: each job's folder written atomically, so `resume` never counts a half-written job.
- `summary`: summary.csv / summary.json.
- `outcome`: job statuses, `Outcome`, and `JobKind`, what another kind of batch job provides to run the same way.

Ray is optional (`pip install 'kitsuke[batch]'`); `LocalRunner` needs nothing more.
"""

from .calibrate_jobs import CalibrateKind
from .jobs import DressKind
from .local import LocalRunner
from .manifest import BodySource, CalibrateJob, Job, read_calibrate_manifest, read_manifest
from .on_ray import RayRunner, ray_available
from .outcome import DONE, FAILED, OK, OUT_OF_TARGET, REFUSED, STATUSES, JobKind, Outcome
from .run import BatchResult, run_batch
from .runners import Runner

__all__ = [
    "DONE",
    "FAILED",
    "OK",
    "OUT_OF_TARGET",
    "REFUSED",
    "STATUSES",
    "BatchResult",
    "BodySource",
    "CalibrateJob",
    "CalibrateKind",
    "DressKind",
    "Job",
    "JobKind",
    "LocalRunner",
    "Outcome",
    "RayRunner",
    "Runner",
    "ray_available",
    "read_calibrate_manifest",
    "read_manifest",
    "run_batch",
]
