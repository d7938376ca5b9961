"""The batch's summary table, one row per manifest job, as CSV (for a spreadsheet) and JSON (for a program).

Columns: id, status (ok, out_of_target, refused, failed; not_run for a job the batch did not reach, when it was
stopped), reason (why refused or failed; the targets missed when out_of_target), seconds (the job's time on its
worker), the job's measures (for a dress: vertices, strain_mean_pct, strain_max_pct, deepest_mm, inside,
seam_gap_mm, inverted, stroke_mm, loose_strokes, wrap_s), worker (host:pid). summary.json also holds the counts
and each job's full record (what the job was, its files).
"""

from __future__ import annotations

import csv
import io
from collections import Counter
from pathlib import Path
from typing import Any

from .._files import write_json_atomic, write_text_atomic
from .outcome import STATUSES
from .outdir import SUMMARY_CSV, SUMMARY_JSON

NOT_RUN = "not_run"
FIRST, LAST = ("id", "status", "reason", "seconds"), ("worker",)


def counts(records: list[dict[str, Any]]) -> dict[str, int]:
    """Jobs per status (every status present, not_run included)."""
    c = Counter(r["status"] for r in records)
    return {s: c.get(s, 0) for s in (*STATUSES, NOT_RUN)}


def summary_rows(jobs: list[Any], records: dict[str, dict[str, Any]]) -> list[dict[str, Any]]:
    """One record per job in manifest order; a job without one gets status not_run."""
    return [records.get(job.id) or {"id": job.id, "status": NOT_RUN, "reason": "", "measures": {}} for job in jobs]


def write_summary(out: Path, rows: list[dict[str, Any]]) -> tuple[Path, Path]:
    """Write OUTDIR/summary.csv and summary.json (atomically); returns their paths."""
    measures: dict[str, None] = {}  # the measure columns, in the order first met
    for r in rows:
        measures.update(dict.fromkeys(r.get("measures") or {}))
    columns = [*FIRST, *measures, *LAST]
    text = io.StringIO()
    writer = csv.DictWriter(text, fieldnames=columns, lineterminator="\n")
    writer.writeheader()
    for r in rows:
        flat = {**(r.get("measures") or {}), **{k: r.get(k, "") for k in (*FIRST, *LAST)}}
        writer.writerow({k: flat.get(k, "") for k in columns})
    csv_path = write_text_atomic(out / SUMMARY_CSV, text.getvalue())
    json_path = write_json_atomic(out / SUMMARY_JSON, {"counts": counts(rows), "jobs": rows})
    return csv_path, json_path
