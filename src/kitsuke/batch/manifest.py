"""A batch manifest: one job per row, as CSV or JSON (`kitsuke batch dress --help` shows both): dress jobs
(`read_manifest`) or kimono calibration jobs (`read_calibrate_manifest`: id, pattern, step, timeout).

CSV: a header row naming the columns, then one job per line; an empty cell takes the default.

    id,body,pattern,strokes,edge_length
    shirt,mean_all.obj,shirt_mean_specification.json,shirt_mean_all.json,
    skirt,mean_all.obj,corpus/gc_s101_0003_specification.json,suggest,2.5

JSON: a list of job objects, or an object `{"defaults": {...}, "jobs": [...]}` whose defaults fill every job.

Relative paths are taken from the manifest's folder, so a manifest travels with its files. A manifest that is not
one (a missing column, an unknown one, a duplicate id, a value out of range) is refused whole, naming the file and
the row, before any job runs: a typo should not cost a thousand jobs. A job's files are read when the job runs: a
missing or broken body, pattern or strokes file refuses that job only.
"""

from __future__ import annotations

import csv
import dataclasses
import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from .._files import read_json, require_file
from ..dressing.options import DressOptions, parse_setting
from ..errors import InputError

#: A job id names its output folder: letters, digits, `.`, `_`, `-`, not starting with a dot (no hidden folders,
#: no `..`), at most 100 characters.
ID_PATTERN = re.compile(r"[A-Za-z0-9_-][A-Za-z0-9._-]{0,99}")
#: `strokes` column value that asks for `kitsuke.dressing.suggest_strokes` instead of a file.
SUGGEST = "suggest"
AXES = ("auto", "+x", "-x", "+y", "-y", "+z", "-z")
UNITS = ("auto", "m", "dm", "cm", "mm", "in")
TARGETS = ("standard", "robust")

#: Every column a manifest may have: name -> what it holds (`kitsuke batch dress --help` lists them). Required ones
#: first.
COLUMNS: dict[str, str] = {
    "id": "the job's name and its output folder OUTDIR/ID (letters, digits, . _ -)",
    "body": "body mesh file (OBJ, GLB, PLY) or `default`",
    "pattern": "pattern file (kitsuke JSON, GarmentCode JSON, SVG)",
    "strokes": "kitsuke strokes JSON, or `suggest` (kitsuke strokes suggest)",
    "edge_length": "garment mesh edge length, cm (default 1.5)",
    "stroke_reach": "how far a stroke may settle from its body stroke, mm (default 8)",
    "hold_strokes": "hang the garment from its strokes (default false)",
    "hang": "how strongly cloth off the body turns down (default: 2 for a kimono, else 0)",
    "no_polish": "skip the polish: faster, more strain (default false)",
    "set": "other wrap settings by dotted name, NAME=VALUE separated by ';' (e.g. polish.rounds=0;settle.method="
    "global; in JSON also an object), as `kitsuke dress --set`",
    "min_area": "suggest only: smallest piece given a stroke, share of the largest (default 0.15)",
    "perturb": "draw the strokes as another hand would (kitsuke.dressing.perturb_strokes), this seed",
    "units": "body file's length unit: " + ", ".join(UNITS) + " (default auto)",
    "up": "body file's up axis: " + ", ".join(AXES) + " (default auto)",
    "facing": "body file's facing axis (default auto)",
    "group": "keep only this OBJ group of the body file",
    "targets": "quality targets deciding ok / out_of_target: standard or robust (default standard)",
    "timeout": "seconds this job may take, over --timeout",
    "glb": "write garment.glb, garment and body (default true)",
    "png": "write views.png, front/side/back (default false; needs EGL on the workers)",
}
REQUIRED = ("id", "body", "pattern", "strokes")
#: The columns of a calibration manifest (`kitsuke batch calibrate`).
CALIBRATE_COLUMNS: dict[str, str] = {
    "id": COLUMNS["id"],
    "pattern": "a kimono pattern (kitsuke pattern kimono, JSON), or `default` (the default kimono)",
    "step": "angle step of E(θ), degrees, dividing 180 (default 15)",
    "timeout": COLUMNS["timeout"],
}
CHOICES = {"units": UNITS, "up": AXES, "facing": AXES, "targets": TARGETS}
TRUE, FALSE = ("true", "yes", "1"), ("false", "no", "0")


@dataclass(frozen=True)
class BodySource:
    """Where a body comes from: a mesh file read with these options, or `default` (the packaged body). Hashable:
    jobs on the same source share one loaded body."""

    path: str
    units: str = "auto"
    up: str = "auto"
    facing: str = "auto"
    group: str | None = None


@dataclass(frozen=True)
class Job:
    """One dress job of a manifest.

    id : its name and output folder. body : where its body comes from. pattern : absolute path. strokes : absolute
    path, or None to suggest them. options : the wrap's options. min_area : suggest's smallest piece share, or
    None (the default). perturb : seed of `perturb_strokes` applied to the strokes (robustness runs), or None.
    targets : "standard" (QualityTargets()) or "robust" (QualityTargets.robust()).
    timeout_s : seconds it may run, or None (the batch's). glb, png : outputs to write. where : "line 4" / "job 3",
    for messages (not part of what the job is).
    """

    id: str
    body: BodySource
    pattern: str
    strokes: str | None
    options: DressOptions = DressOptions()
    min_area: float | None = None
    perturb: int | None = None
    targets: str = "standard"
    timeout_s: float | None = None
    glb: bool = True
    png: bool = False
    where: str = field(default="", compare=False)

    def spec(self) -> dict[str, Any]:
        """JSON-ready: what the job is (recorded with its result; `--resume` reruns a job whose spec changed)."""
        d = dataclasses.asdict(self)
        del d["where"]
        return d


@dataclass(frozen=True)
class CalibrateJob:
    """One kimono calibration job (`kitsuke kimono calibrate` on the default body). pattern : absolute path of a
    kimono pattern, or "default". step_deg : the angle step. timeout_s, where : as `Job`'s."""

    id: str
    pattern: str
    step_deg: float = 15.0
    timeout_s: float | None = None
    where: str = field(default="", compare=False)

    def spec(self) -> dict[str, Any]:
        d = dataclasses.asdict(self)
        del d["where"]
        return d


def read_manifest(path: str | Path) -> list[Job]:
    """The dress jobs of a CSV (`.csv`) or JSON manifest, in order; InputError naming the file and row otherwise."""
    return _read(path, COLUMNS, _job)


def read_calibrate_manifest(path: str | Path) -> list[CalibrateJob]:
    """The calibration jobs of a CSV or JSON manifest (`CALIBRATE_COLUMNS`), as `read_manifest` reads dress jobs."""
    return _read(path, CALIBRATE_COLUMNS, _calibrate_job)


def _read(path: str | Path, columns: dict[str, str], make) -> list:  # noqa: ANN001
    p = require_file(path, what="manifest")
    rows = _csv_rows(p, columns) if p.suffix.lower() == ".csv" else _json_rows(p, columns)
    if not rows:
        raise InputError("the manifest lists no jobs", p)
    jobs, seen = [], {}
    for where, row in rows:
        try:
            job = make(row, p.parent, where)
        except InputError as e:
            raise InputError(f"{where}: {e.message}", p) from None
        if job.id in seen:
            raise InputError(f"{where}: id {job.id!r} is already used ({seen[job.id]})", p)
        seen[job.id] = where
        jobs.append(job)
    return jobs


def _csv_rows(path: Path, columns: dict[str, str]) -> list[tuple[str, dict[str, str]]]:
    try:
        text = path.read_text(encoding="utf-8-sig")  # -sig: spreadsheets write a byte-order mark
    except UnicodeDecodeError:
        raise InputError("not a text manifest (not UTF-8)", path) from None
    reader = csv.reader(text.splitlines())
    header = [h.strip() for h in next(reader, [])]
    for h in header:
        if h not in columns:
            raise InputError(f"line 1: unknown column {h!r} (known: {', '.join(columns)})", path)
    rows = []
    for cells in reader:
        where = f"line {reader.line_num}"
        if not any(c.strip() for c in cells):
            continue  # blank lines, e.g. at the end
        if len(cells) != len(header):
            raise InputError(f"{where}: {len(cells)} cells, the header names {len(header)} columns", path)
        rows.append((where, {h: c.strip() for h, c in zip(header, cells) if c.strip() != ""}))
    return rows


def _json_rows(path: Path, columns: dict[str, str]) -> list[tuple[str, dict[str, Any]]]:
    data = read_json(path, what="manifest")
    defaults: dict[str, Any] = {}
    if isinstance(data, dict):
        defaults, data = data.get("defaults", {}), data.get("jobs")
        if not isinstance(defaults, dict):
            raise InputError("'defaults' must be an object of column values", path)
    if not isinstance(data, list):
        raise InputError("expected a list of jobs, or an object with 'jobs' (a list) and 'defaults'", path)
    rows = []
    for k, row in enumerate(data, start=1):
        if not isinstance(row, dict):
            raise InputError(f"job {k}: expected an object of column values, got {type(row).__name__}", path)
        merged = {**defaults, **row}
        for name in merged:
            if name not in columns:
                raise InputError(f"job {k}: unknown key {name!r} (known: {', '.join(columns)})", path)
        rows.append((f"job {k}", {n: v for n, v in merged.items() if v is not None and v != ""}))
    return rows


def _job_id(row: dict[str, Any], required: tuple[str, ...]) -> str:
    for name in required:
        if name not in row:
            raise InputError(f"no {name!r}")
    job_id = _text(row, "id")
    if not ID_PATTERN.fullmatch(job_id):
        raise InputError(f"id {job_id!r} cannot name a folder: use letters, digits, . _ - (not starting with .)")
    return job_id


def _timeout(row: dict[str, Any]) -> float | None:
    timeout = _number(row, "timeout", None)
    if timeout is not None and not timeout > 0:
        raise InputError(f"timeout must be a positive number of seconds, got {timeout}")
    return timeout


def _calibrate_job(row: dict[str, Any], folder: Path, where: str) -> CalibrateJob:
    job_id = _job_id(row, ("id", "pattern"))
    step = _number(row, "step", 15.0)
    n = 180.0 / step if step > 0 else math.inf
    if not (math.isfinite(n) and abs(n - round(n)) < 1e-9):
        raise InputError(f"step must divide 180 degrees, got {step:g}")
    pattern = _text(row, "pattern")
    return CalibrateJob(
        id=job_id,
        pattern=pattern if pattern == "default" else _path(folder, pattern),
        step_deg=step,
        timeout_s=_timeout(row),
        where=where,
    )


def _job(row: dict[str, Any], folder: Path, where: str) -> Job:
    job_id = _job_id(row, REQUIRED)
    strokes = _text(row, "strokes")
    options = DressOptions(
        edge_length=_number(row, "edge_length", 1.5),
        stroke_reach=_number(row, "stroke_reach", 8.0),
        hold_strokes=_bool(row, "hold_strokes", False),
        hang=_number(row, "hang", None),
        no_polish=_bool(row, "no_polish", False),
        settings=_settings(row),
    )
    options.check(spell=lambda name: "set" if name == "settings" else name)
    min_area = _number(row, "min_area", None)
    if min_area is not None:
        if strokes != SUGGEST:
            raise InputError("min_area is for suggested strokes (strokes = suggest)")
        if not 0.0 <= min_area <= 1.0:
            raise InputError(f"min_area must be a share between 0 and 1, got {min_area}")
    perturb = _number(row, "perturb", None)
    if perturb is not None and not (perturb >= 0 and perturb == int(perturb)):
        raise InputError(f"perturb must be a seed, an integer >= 0, got {row['perturb']!r}")
    timeout = _timeout(row)
    body = _text(row, "body")
    return Job(
        id=job_id,
        body=BodySource(
            path=body if body == "default" else _path(folder, body),
            units=_choice(row, "units"),
            up=_choice(row, "up"),
            facing=_choice(row, "facing"),
            group=row.get("group") and _text(row, "group"),
        ),
        pattern=_path(folder, _text(row, "pattern")),
        strokes=None if strokes == SUGGEST else _path(folder, strokes),
        options=options,
        min_area=min_area,
        perturb=None if perturb is None else int(perturb),
        targets=_choice(row, "targets", "standard"),
        timeout_s=timeout,
        glb=_bool(row, "glb", True),
        png=_bool(row, "png", False),
        where=where,
    )


def _settings(row: dict[str, Any]) -> tuple[tuple[str, Any], ...]:
    """The `set` column: "NAME=VALUE;NAME=VALUE" (`parse_setting`), or in JSON an object {name: value}."""
    value = row.get("set")
    if value is None or value == "":
        return ()
    if isinstance(value, dict):
        return tuple(value.items())
    if isinstance(value, str):
        return tuple(parse_setting(part) for part in value.split(";") if part.strip())
    raise InputError(f"set must be NAME=VALUE;... or an object of settings, got {value!r}")


def _path(folder: Path, value: str) -> str:
    return str((folder / Path(value).expanduser()).absolute())


def _text(row: dict[str, Any], name: str) -> str:
    value = row[name]
    if not isinstance(value, str) or not value.strip():
        raise InputError(f"{name} must be a non-empty text, got {value!r}")
    return value.strip()


def _choice(row: dict[str, Any], name: str, default: str = "auto") -> str:
    value = row.get(name, default)
    if value not in CHOICES[name]:
        raise InputError(f"{name} must be one of {', '.join(CHOICES[name])}, got {value!r}")
    return value


def _number(row: dict[str, Any], name: str, default: float | None) -> float | None:
    value = row.get(name)
    if value is None:
        return default
    try:
        number = float(value) if not isinstance(value, bool) else math.nan
    except (TypeError, ValueError):
        number = math.nan
    if not math.isfinite(number):
        raise InputError(f"{name} must be a number, got {value!r}")
    return number


def _bool(row: dict[str, Any], name: str, default: bool) -> bool:
    value = row.get(name)
    if value is None:
        return default
    if isinstance(value, bool):
        return value
    if isinstance(value, str) and value.strip().lower() in TRUE + FALSE:
        return value.strip().lower() in TRUE
    raise InputError(f"{name} must be true or false, got {value!r}")
