"""The runners with a job kind that misbehaves on purpose (tests/batch/toy.py): failures stay with their job and
the batch goes on, workers warm once, shared inputs are read once, job folders are atomic and --resume runs only
what is missing. Each test runs on the local process pool and on Ray."""

from __future__ import annotations

import json

import pytest

from kitsuke.batch import run_batch
from kitsuke.batch.outdir import RECORD
from kitsuke.errors import ComputationError, InputError

from .conftest import make_runner
from .toy import ToyJob, ToyKind


def statuses(result_dir):
    rows = json.loads((result_dir / "summary.json").read_text())["jobs"]
    return {r["id"]: r for r in rows}


def test_failures_stay_with_their_job(tmp_path, runner_kind):
    jobs = [
        ToyJob("a"),
        ToyJob("raises", "raise"),
        ToyJob("dies", "die"),
        ToyJob("hangs", "hang", timeout_s=1.0),
        ToyJob("fails", "fail"),
        ToyJob("silk", word="silk"),
        ToyJob("unreadable", word="bad"),
        ToyJob("b"),
    ]
    kind = ToyKind()
    result = run_batch(kind, jobs, tmp_path / "out", make_runner(runner_kind, workers=2), progress=False)
    rows = statuses(tmp_path / "out")
    assert list(rows) == [j.id for j in jobs]  # manifest order
    assert {k: r["status"] for k, r in rows.items()} == {
        "a": "ok",
        "raises": "failed",
        "dies": "failed",
        "hangs": "failed",
        "fails": "failed",
        "silk": "ok",
        "unreadable": "refused",
        "b": "ok",
    }
    assert rows["raises"]["reason"] == "internal error: ValueError: job raises raised"
    assert rows["dies"]["reason"].startswith("its worker died")
    assert rows["hangs"]["reason"] == "timed out after 1 s (its worker was stopped)"
    assert rows["fails"]["reason"] == "a computation that gave nothing"
    assert rows["unreadable"]["reason"] == "bad: cannot read this word"
    assert result.counts == {"ok": 3, "out_of_target": 0, "refused": 1, "failed": 4, "not_run": 0}
    assert (tmp_path / "out" / "silk" / "word.txt").read_text() == "SILK"
    assert not (tmp_path / "out" / "dies" / "word.txt").exists()
    # Each shared input read once by the driver, however many jobs and workers used it.
    assert sorted(kind.loads) == [("word", "bad"), ("word", "cloth"), ("word", "silk")]


def test_workers_warm_once_and_keep_their_inputs(tmp_path, runner_kind):
    jobs = [ToyJob(f"j{k}", word="cloth" if k % 2 else "silk") for k in range(8)]
    run_batch(ToyKind(), jobs, tmp_path / "out", make_runner(runner_kind, workers=2), progress=False)
    measures = [r["measures"] for r in statuses(tmp_path / "out").values()]
    assert {m["warmed"] for m in measures} == {1}  # never warmed again for a job
    by_worker: dict[int, list[int]] = {}
    for m in measures:
        by_worker.setdefault(m["pid"], []).append(m["jobs"])
    assert 1 <= len(by_worker) <= 2 and sum(len(v) for v in by_worker.values()) == 8
    assert all(sorted(v) == list(range(1, len(v) + 1)) for v in by_worker.values())
    assert {m["length"] for m in measures} == {5, 4}


def test_resume_runs_only_what_is_missing(tmp_path, runner_kind):
    out = tmp_path / "out"
    jobs = [ToyJob(f"j{k}") for k in range(4)] + [ToyJob("flaky", "fail")]
    run_batch(ToyKind(), jobs, out, make_runner(runner_kind, workers=2), progress=False)
    before = {j.id: (out / j.id / RECORD).read_bytes() for j in jobs}
    # What a kill leaves: a job's folder never renamed into place, another job never reached.
    (out / ".partial-j3-abc").mkdir()
    (out / ".partial-j3-abc" / "word.txt").write_text("half")
    for p in (out / "j3").iterdir():
        p.unlink()
    (out / "j3").rmdir()
    with pytest.raises(InputError, match="is not empty: --resume"):
        run_batch(ToyKind(), jobs, out, make_runner(runner_kind, workers=2), progress=False)
    result = run_batch(ToyKind(), jobs, out, make_runner(runner_kind, workers=2), resume=True, progress=False)
    assert (result.ran, result.skipped) == (1, 4)
    assert not list(out.glob(".partial-*"))
    assert all((out / j.id / RECORD).read_bytes() == before[j.id] for j in jobs if j.id != "j3")
    assert statuses(out)["j3"]["status"] == "ok"
    # --retry-failed runs the failed job again; a changed job runs again too.
    changed = [*jobs[:4], ToyJob("flaky", "ok")]
    result = run_batch(ToyKind(), changed, out, make_runner(runner_kind, workers=2), resume=True, progress=False)
    assert (result.ran, result.counts["ok"]) == (1, 5)


def test_workers_that_cannot_warm_up_stop_the_batch(tmp_path, runner_kind):
    jobs = [ToyJob("a"), ToyJob("b")]
    with pytest.raises(ComputationError, match="no worker could start: .*RuntimeError: no kernels here"):
        run_batch(ToyKind(warm_fails=True), jobs, tmp_path / "out", make_runner(runner_kind, workers=1), progress=False)
    assert [r["status"] for r in statuses(tmp_path / "out").values()] == ["not_run", "not_run"]
