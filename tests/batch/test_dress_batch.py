"""`kitsuke batch dress` on real garments: a 6-job manifest (a broken pattern and a job past its time limit among
them) on 2 workers gives each good job exactly what `kitsuke dress` (and `kitsuke strokes suggest`) give in one
process, isolates the two bad ones with their reason; a batch killed mid-run finishes with --resume, running only
what it had not finished. On Ray and on the local process pool."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time

import pytest

from .conftest import MEAN_ALL, PATTERNS, ROOT, STROKES, write_csv

pytestmark = pytest.mark.slow

SHIRT = PATTERNS / "shirt_mean_specification.json"
HOODY = PATTERNS / "hoody_mean_specification.json"
TSHIRT = PATTERNS / "teagan_tshirt_cisMaleAdult42_sewn.json"
SKIRT = PATTERNS / "corpus" / "gc_s101_0003_specification.json"

#: id -> (manifest row, the same job's `kitsuke dress` options, or None for a job that must not give a garment).
JOBS = {
    "slow": ({"body": MEAN_ALL, "pattern": SHIRT, "strokes": STROKES / "shirt_mean_all.json", "timeout": 0.5}, None),
    "shirt": ({"body": MEAN_ALL, "pattern": SHIRT, "strokes": STROKES / "shirt_mean_all.json"}, []),
    "tshirt": ({"body": "default", "pattern": TSHIRT, "strokes": STROKES / "tshirt_default.json"}, []),
    "broken": ({"body": MEAN_ALL, "pattern": "broken.json", "strokes": "suggest"}, None),
    "skirt": ({"body": MEAN_ALL, "pattern": SKIRT, "strokes": "suggest"}, []),
    "hoody": (
        {"body": MEAN_ALL, "pattern": HOODY, "strokes": STROKES / "hoody_mean_all.json", "edge_length": 2.5,
         "no_polish": "true"},
        ["--edge-length", "2.5", "--no-polish"],
    ),
}  # fmt: skip


def manifest(folder):
    (folder / "broken.json").write_text('{"panels": ')  # a pattern file cut short
    return write_csv(folder / "jobs.csv", [{"id": k, **row} for k, (row, _) in JOBS.items()])


def report_without_timings(path):
    d = json.loads(path.read_text())
    d.pop("timings_s")
    return d


@pytest.fixture(scope="module")
def single_process(tmp_path_factory):
    """Each good job dressed by `kitsuke dress` in this process (the skirt's strokes by `kitsuke strokes
    suggest`): id -> folder with garment.obj, garment.glb, report.json."""
    from kitsuke.cli import main

    base = tmp_path_factory.mktemp("single")
    for job, (row, options) in JOBS.items():
        if options is None:
            continue
        out = base / job
        out.mkdir()
        strokes = row["strokes"]
        if strokes == "suggest":
            strokes = out / "strokes.json"
            assert main(["strokes", "suggest", "--body", str(row["body"]), "--pattern", str(row["pattern"]),
                         "-o", str(strokes)]) == 0  # fmt: skip
        args = ["dress", "--body", str(row["body"]), "--pattern", str(row["pattern"]), "--strokes", str(strokes)]
        out_args = ["-o", str(out / "garment.glb"), "--obj", str(out / "garment.obj"), "--report", str(out / "r.json")]
        assert main([*args, *out_args, *options]) == 0
    return base


def test_six_jobs_on_two_workers(tmp_path, run_cli, runner_kind, single_process):
    m = manifest(tmp_path)
    out = tmp_path / "out"
    where = ["--local"] if runner_kind == "local" else []
    r = run_cli("batch", "dress", m, "-o", out, "--workers", "2", *where)
    # Two jobs gave no garment: exit 1, one line naming the summary.
    assert r.code == 1
    last = r.err.strip().splitlines()[-1]
    assert last == f"kitsuke: failed: batch: 2 of 6 jobs gave no garment: see {out}/summary.csv"
    rows = {row["id"]: row for row in json.loads((out / "summary.json").read_text())["jobs"]}
    assert {k: v["status"] for k, v in rows.items()} == {
        "slow": "failed",
        "shirt": "ok",
        "tshirt": "ok",
        "broken": "refused",
        "skirt": "out_of_target",
        "hoody": "out_of_target",
    }
    assert rows["slow"]["reason"] == "timed out after 0.5 s (its worker was stopped)"
    assert rows["broken"]["reason"].startswith(f"{tmp_path / 'broken.json'}: invalid JSON")
    assert rows["skirt"]["reason"].startswith("max edge strain")
    # The good jobs: exactly what one process gives (float32 GLB, 7-decimal OBJ, the report's float64 measures).
    for job in ("shirt", "tshirt", "skirt", "hoody"):
        mine, ref = out / job, single_process / job
        assert (mine / "garment.obj").read_bytes() == (ref / "garment.obj").read_bytes(), job
        assert (mine / "garment.glb").read_bytes() == (ref / "garment.glb").read_bytes(), job
        assert report_without_timings(mine / "report.json") == report_without_timings(ref / "r.json"), job
        quality = json.loads((ref / "r.json").read_text())["quality"]
        assert rows[job]["measures"]["strain_max_pct"] == round(100 * quality["strain_max"], 3)
    assert (out / "skirt" / "strokes.json").read_bytes() == (single_process / "skirt" / "strokes.json").read_bytes()
    assert sorted(p.name for p in (out / "broken").iterdir()) == ["result.json"]
    header = (out / "summary.csv").read_text().splitlines()[0]
    assert header.startswith("id,status,reason,seconds,vertices,strain_mean_pct,strain_max_pct,deepest_mm")


def quick_jobs(folder, n):
    """n quick jobs (GarmentCode's hoody without the polish, at n edge lengths: ~0.5 s each)."""
    rows = [
        {"id": f"hoody{k}", "body": MEAN_ALL, "pattern": HOODY, "strokes": STROKES / "hoody_mean_all.json",
         "edge_length": 2.5 + 0.25 * k, "no_polish": "true"}
        for k in range(n)
    ]  # fmt: skip
    return write_csv(folder / "jobs.csv", rows)


def test_resume_after_a_kill_finishes_only_what_is_missing(tmp_path, run_cli, runner_kind):
    m = quick_jobs(tmp_path, 5)
    out = tmp_path / "out"
    where = ["--local"] if runner_kind == "local" else []
    cmd = [sys.executable, "-m", "kitsuke", "batch", "dress", str(m), "-o", str(out), "--workers", "1", *where]
    proc = subprocess.Popen(cmd, cwd=ROOT, stderr=subprocess.PIPE, start_new_session=True)
    try:
        deadline = time.monotonic() + 120
        while not any(p.is_dir() and not p.name.startswith(".") for p in out.glob("*")):
            assert proc.poll() is None and time.monotonic() < deadline, proc.stderr.read().decode()
            time.sleep(0.02)
        proc.kill()  # the batch's own process, at once: no cleanup of its own
        proc.wait()
    finally:
        try:
            os.killpg(proc.pid, signal.SIGKILL)  # what it started in its group (its Ray), if anything is left
        except ProcessLookupError:
            pass
    finished = {p.name: (p / "result.json").read_bytes() for p in out.iterdir() if p.is_dir() and p.name[0] != "."}
    assert 1 <= len(finished) < 5
    assert all(json.loads(v)["status"] == "out_of_target" for v in finished.values())  # whole folders only

    r = run_cli("batch", "dress", m, "-o", out, "--workers", "2", "--resume", *where)
    assert r.code == 0, r.err
    assert f"ran {5 - len(finished)} in" in r.err and f"{len(finished)} finished before" in r.err
    assert all((out / k / "result.json").read_bytes() == v for k, v in finished.items())  # not run again
    rows = json.loads((out / "summary.json").read_text())["jobs"]
    assert [row["status"] for row in rows] == ["out_of_target"] * 5
    assert not list(out.glob(".partial-*"))
