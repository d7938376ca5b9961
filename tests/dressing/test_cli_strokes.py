"""`kitsuke strokes suggest / check`, and `kitsuke dress` on strokes no garment can meet (exit 1, nothing
written, `--keep-failed`)."""

from __future__ import annotations

import importlib
import json

import pytest

from kitsuke.dressing import read_strokes
from kitsuke.errors import ComputationError

from ..conftest import DATA

MEAN_ALL = DATA / "bodies" / "mean_all.obj"
SHIRT = DATA / "pattern" / "shirt_mean_specification.json"
TSHIRT = DATA / "pattern" / "teagan_tshirt_cisMaleAdult42_sewn.json"


@pytest.fixture(scope="module")
def suggested(tmp_path_factory):
    from kitsuke.cli import main

    out = tmp_path_factory.mktemp("suggest") / "shirt_strokes.json"
    assert main(["strokes", "suggest", "--body", str(MEAN_ALL), "--pattern", str(SHIRT), "-o", str(out)]) == 0
    return out


def test_suggest_writes_a_strokes_file_that_check_accepts(run_cli, suggested):
    strokes = read_strokes(suggested)
    assert len(strokes) == 8 and strokes.meta["made_by"] == "kitsuke strokes suggest"
    r = run_cli("strokes", "check", "--body", MEAN_ALL, "--pattern", SHIRT, "--strokes", suggested)
    assert r.code == 0, r.err
    lines = r.out.strip().splitlines()
    assert len(lines) == 8 and all(line.startswith("stroke ") and "ratio" in line for line in lines)


def test_suggest_refuses_a_pattern_without_placement_in_one_line(run_cli, tmp_path):
    out = tmp_path / "s.json"
    r = run_cli("strokes", "suggest", "--body", MEAN_ALL, "--pattern", TSHIRT, "-o", out)
    assert r.code == 2 and not out.exists()
    assert len(r.err.strip().splitlines()) == 1 and "carries no placement" in r.err and TSHIRT.name in r.err


@pytest.mark.slow
def test_dress_exits_1_on_strokes_no_garment_can_meet_and_keeps_the_result_only_when_asked(
    run_cli, suggested, tmp_path, monkeypatch
):
    # The front torso's stroke drawn on the back of the body as well: one piece on both sides of the torso.
    doc = json.loads(suggested.read_text())
    front = next(p for p in doc["pairs"] if p["pattern"]["piece"] == "left_ftorso")
    back = next(p for p in doc["pairs"] if p["pattern"]["piece"] == "left_btorso")
    front["body"]["points"] = [[-x, y, z] for x, y, z in back["body"]["points"]]
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(doc))
    out, report = tmp_path / "shirt.glb", tmp_path / "shirt.json"
    args = ("dress", "--body", MEAN_ALL, "--pattern", SHIRT, "--strokes", bad, "-o", out, "--report", report)
    # The failing wrap runs once (it tries grown, laid and sewn: half a minute); the second command meets its error.
    wrap_module = importlib.import_module("kitsuke.dressing.wrap")  # the module, not the function of its name
    real, failures = wrap_module.wrap, []

    def recording(*a, **k):  # noqa: ANN002, ANN003
        try:
            return real(*a, **k)
        except ComputationError as e:
            failures.append(e)
            raise

    monkeypatch.setattr(wrap_module, "wrap", recording)
    r = run_cli(*args, "--no-polish", "--keep-failed")
    assert r.code == 1 and failures[-1].result is not None  # the last: the relay's tries call wrap too
    said = r.err.strip().splitlines()
    assert said[-1].startswith("kitsuke: failed: wrap") and "kept the failed result" in said[0] and len(said) == 2
    assert (tmp_path / "shirt.failed.glb").exists() and (tmp_path / "shirt.failed.json").exists()
    assert not out.exists() and not report.exists()
    for kept in tmp_path.glob("shirt.failed.*"):
        kept.unlink()

    def failing(*a, **k):  # noqa: ANN002, ANN003
        raise failures[-1]

    monkeypatch.setattr(wrap_module, "wrap", failing)
    r = run_cli(*args, "--no-polish")
    assert r.code == 1
    assert r.err.startswith("kitsuke: failed: wrap") and len(r.err.strip().splitlines()) == 1
    assert not any(tmp_path.glob("shirt*"))  # nothing written without --keep-failed


def test_dress_on_suggested_strokes_reports_what_it_misses(run_cli, suggested, tmp_path):
    out, report = tmp_path / "shirt.glb", tmp_path / "shirt.json"
    r = run_cli("dress", "--body", MEAN_ALL, "--pattern", SHIRT, "--strokes", suggested, "-o", out, "--report", report)
    assert r.code == 0, r.err
    summary = json.loads(report.read_text())
    assert isinstance(summary["targets_missed"], list)
    said = r.err.strip().splitlines()[-1]
    assert ("all quality targets met" in said) == (summary["targets_missed"] == [])


@pytest.mark.parametrize(
    ("flag", "value"),
    [("--min-area", v) for v in ("nan", "-0.1", "1.5")] + [("--min-area-cm2", v) for v in ("nan", "-5")],
)
def test_suggest_refuses_a_bad_min_area_naming_the_flag(run_cli, tmp_path, flag, value):
    out = tmp_path / "s.json"
    r = run_cli("strokes", "suggest", "--body", MEAN_ALL, "--pattern", SHIRT, "-o", out, flag, value)
    assert r.code == 2 and f"{flag} must" in r.err and len(r.err.strip().splitlines()) == 1 and not out.exists()


@pytest.mark.slow
def test_suggest_raises_a_skirt_laid_at_the_hips_and_says_so(run_cli, tmp_path):
    skirt = DATA / "pattern" / "corpus" / "gc_s6297_0001_specification.json"
    out = tmp_path / "skirt.json"
    r = run_cli("strokes", "suggest", "--body", MEAN_ALL, "--pattern", skirt, "-o", out)
    assert r.code == 0, r.err
    raised = read_strokes(out).meta["raised_m"]
    assert raised >= 0.08 and f"raised {100 * raised:.0f} cm" in r.err
    kept = tmp_path / "kept.json"
    r = run_cli("strokes", "suggest", "--body", MEAN_ALL, "--pattern", skirt, "-o", kept, "--no-raise")
    assert r.code == 0 and "raised" not in r.err
    # Left where it rests, its strokes lie lower on the body.
    low = min(p.body.points[:, 1].max() for p in read_strokes(kept).pairs)
    high = min(p.body.points[:, 1].max() for p in read_strokes(out).pairs)
    assert high >= low + 0.05
