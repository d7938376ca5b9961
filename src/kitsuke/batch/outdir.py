"""A batch's output folder: one folder per finished job, each written whole or not at all.

    OUTDIR/<job id>/result.json     what the job was, its status, reason, measures, time, worker
    OUTDIR/<job id>/garment.obj ... its outputs (jobs that were refused or failed: result.json only)
    OUTDIR/summary.csv, summary.json
    OUTDIR/.logs/                   local workers' stdout and stderr

A job's folder is built as a hidden `.partial-*` folder beside it and renamed into place when complete, so a
batch killed at any moment leaves either the whole folder or none: `--resume` counts a job as finished exactly
when its folder exists with the same job in its result.json. Left-over partial folders are removed on resume.
"""

from __future__ import annotations

import datetime
import json
import os
import shutil
import tempfile
from pathlib import Path
from typing import Any

from .._files import check_output_folder, write_bytes_atomic, write_json_atomic
from ..errors import InputError
from .outcome import FAILED, Outcome

RECORD = "result.json"
#: Names in OUTDIR that are not job folders (job ids cannot start with a dot; these two are checked for).
SUMMARY_CSV, SUMMARY_JSON = "summary.csv", "summary.json"
RESERVED = (SUMMARY_CSV, SUMMARY_JSON)
LOGS = ".logs"
PARTIAL = ".partial-"


def open_outdir(path: str | os.PathLike[str], *, resume: bool) -> Path:
    """OUTDIR made ready: created if new (its parent must exist); an existing one holding anything is refused
    unless resuming (nothing is overwritten by accident). Partial folders of a killed run are removed."""
    out = Path(path)
    if out.exists() and not out.is_dir():
        raise InputError("is a file; the output of a batch is a folder", out)
    if out.is_dir() and not resume and any(out.iterdir()):
        raise InputError("is not empty: --resume finishes the batch written there; or choose a new folder", out)
    if not out.exists():
        check_output_folder(out)
        out.mkdir()
    for stale in out.glob(PARTIAL + "*"):
        shutil.rmtree(stale, ignore_errors=True)
    return out


def check_ids(jobs: list[Any]) -> None:
    """Refuse job ids that would collide with the batch's own files."""
    for job in jobs:
        if job.id in RESERVED:
            raise InputError(f"{job.where}: id {job.id!r} is the name of the batch's summary; choose another")


def read_record(out: Path, job_id: str) -> dict[str, Any] | None:
    """The record of a finished job, or None (no folder, or an unreadable record: then the job runs again)."""
    try:
        return json.loads((out / job_id / RECORD).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None


def finished(out: Path, jobs: list[Any], *, retry_failed: bool = False) -> dict[str, dict[str, Any]]:
    """Records of the jobs already finished in `out`, by id: their folder exists and holds the same job (a job
    whose manifest row changed runs again). With retry_failed, failed jobs count as not finished."""
    done = {}
    for job in jobs:
        record = read_record(out, job.id)
        if record is None or record.get("job") != _plain(job.spec()):
            continue
        if retry_failed and record.get("status") == FAILED:
            continue
        done[job.id] = record
    return done


def write_job(out: Path, job: Any, outcome: Outcome) -> dict[str, Any]:
    """Write the job's outputs and record into OUTDIR/<id>/, atomically (see the module docstring); returns the
    record."""
    record = {
        "id": job.id,
        "status": outcome.status,
        "reason": outcome.reason,
        "seconds": round(outcome.seconds, 3),
        "measures": outcome.measures,
        "files": sorted(outcome.files),
        "worker": outcome.worker,
        "finished": datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds"),
        "job": _plain(job.spec()),
    }
    partial = Path(tempfile.mkdtemp(prefix=f"{PARTIAL}{job.id}-", dir=out))
    try:
        for name, data in outcome.files.items():
            write_bytes_atomic(partial / name, data)
        write_json_atomic(partial / RECORD, record)
        os.chmod(partial, 0o777 & ~_umask())  # mkdtemp makes it 0700: give it a normal folder's permissions
        final = out / job.id
        if final.exists():
            # A job run again (--retry-failed, or its row changed): the old folder steps aside for the new one.
            old = Path(tempfile.mkdtemp(prefix=f"{PARTIAL}old-{job.id}-", dir=out))
            os.replace(final, old / job.id)
            os.replace(partial, final)
            shutil.rmtree(old, ignore_errors=True)
        else:
            os.replace(partial, final)
    except BaseException:
        shutil.rmtree(partial, ignore_errors=True)
        raise
    return record


def _plain(value: Any) -> Any:
    """`value` as JSON gives it back (tuples as lists), so a stored job compares equal to a fresh spec."""
    return json.loads(json.dumps(value))


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask
