"""Manifests: CSV and JSON read into jobs (paths from the manifest's folder, defaults, options as `kitsuke dress`
takes them); anything that is not a manifest refused whole, naming the file and the row, before any job runs."""

from __future__ import annotations

import json
import sys

import pytest

from kitsuke.batch import read_manifest
from kitsuke.batch.manifest import BodySource
from kitsuke.dressing.options import DressOptions
from kitsuke.errors import InputError

from .conftest import write_csv


def test_csv_rows_become_jobs(tmp_path):
    m = write_csv(
        tmp_path / "jobs.csv",
        [
            {"id": "shirt", "body": "bodies/mean_all.obj", "pattern": "shirt.json", "strokes": "s.json"},
            {"id": "skirt", "body": "default", "pattern": "/data/skirt.json", "strokes": "suggest",
             "edge_length": "2.5", "no_polish": "yes", "min_area": "0.3", "perturb": "7", "targets": "robust",
             "timeout": "90", "units": "cm", "png": "true"},
        ],
    )  # fmt: skip
    shirt, skirt = read_manifest(m)
    assert shirt.body == BodySource(str(tmp_path / "bodies" / "mean_all.obj"))
    assert (shirt.pattern, shirt.strokes) == (str(tmp_path / "shirt.json"), str(tmp_path / "s.json"))
    assert (shirt.options, shirt.targets, shirt.timeout_s, shirt.glb, shirt.png) == (
        DressOptions(),
        "standard",
        None,
        True,
        False,
    )
    assert skirt.body == BodySource("default", units="cm")
    assert (skirt.pattern, skirt.strokes, skirt.min_area, skirt.perturb) == ("/data/skirt.json", None, 0.3, 7)
    assert skirt.options == DressOptions(edge_length=2.5, no_polish=True)
    assert (skirt.targets, skirt.timeout_s, skirt.png) == ("robust", 90.0, True)
    assert skirt.where == "line 3"


def test_json_with_defaults(tmp_path):
    m = tmp_path / "jobs.json"
    m.write_text(json.dumps({
        "defaults": {"body": "default", "strokes": "suggest", "hang": 1},
        "jobs": [{"id": "a", "pattern": "a.json"},
                 {"id": "b", "pattern": "b.json", "hang": None, "hold_strokes": True}],
    }))  # fmt: skip
    a, b = read_manifest(m)
    assert a.options == DressOptions(hang=1.0) and a.strokes is None
    assert b.options == DressOptions(hold_strokes=True)  # null: the default, not the manifest's default
    assert read_manifest(_json(tmp_path, [{"id": "c", "body": "x", "pattern": "p", "strokes": "s"}]))[0].id == "c"


def test_wrap_settings_column(tmp_path):
    """`set`: any wrap setting by dotted name, as `kitsuke dress --set`, in CSV text or a JSON object; the job's
    wrap takes it."""
    from kitsuke.body import default_body
    from kitsuke.pattern import default_kimono

    csv = tmp_path / "jobs.csv"
    csv.write_text("id,body,pattern,strokes,set\na,default,p.json,s.json,polish.rounds=0; settle.method=global\n")
    (job,) = read_manifest(csv)
    assert job.options.settings == (("polish.rounds", 0), ("settle.method", "global"))
    row = {**ROW, "set": {"grow.hang": 1.5, "tethers.reach_m": None}}
    (other,) = read_manifest(_json(tmp_path, [row]))
    params = other.options.wrap_params(default_body(), default_kimono())
    assert params.grow.hang == 1.5 and params.tethers.reach_m is None
    assert job.options.wrap_params(default_body(), default_kimono()).polish.rounds == 0


def _json(tmp_path, rows):
    p = tmp_path / "list.json"
    p.write_text(json.dumps(rows))
    return p


ROW = {"id": "a", "body": "default", "pattern": "p.json", "strokes": "suggest"}


@pytest.mark.parametrize(
    "change, message",
    [
        ({"edge_lenght": "2"}, "line 1: unknown column 'edge_lenght'"),
        ({"strokes": ""}, "line 2: no 'strokes'"),
        ({"id": "../up"}, "line 2: id '../up' cannot name a folder"),
        ({"id": ".hidden"}, "cannot name a folder"),
        ({"edge_length": "20"}, "line 2: edge_length must be between 0.2 and 10 cm, got 20.0"),
        ({"stroke_reach": "far"}, "line 2: stroke_reach must be a number, got 'far'"),
        ({"no_polish": "maybe"}, "line 2: no_polish must be true or false, got 'maybe'"),
        ({"up": "+w"}, "line 2: up must be one of auto, +x"),
        ({"timeout": "0"}, "line 2: timeout must be a positive number of seconds"),
        ({"strokes": "s.json", "min_area": "0.2"}, "line 2: min_area is for suggested strokes"),
        ({"targets": "loose"}, "targets must be one of standard, robust"),
        ({"perturb": "1.5"}, "line 2: perturb must be a seed, an integer >= 0, got '1.5'"),
        ({"set": "polish.roundz=0"}, "line 2: set: no wrap setting 'polish.roundz'"),
        ({"set": "polish"}, "line 2: a wrap setting is NAME=VALUE"),
    ],
)
def test_bad_csv_refused_naming_file_and_row(tmp_path, change, message):
    m = write_csv(tmp_path / "jobs.csv", [{**ROW, **change}])
    with pytest.raises(InputError) as e:
        read_manifest(m)
    assert str(e.value).startswith(f"{m}: ") and message in str(e.value)


def test_duplicate_ids_and_other_shapes_refused(tmp_path):
    m = write_csv(tmp_path / "jobs.csv", [ROW, {**ROW, "pattern": "q.json"}])
    with pytest.raises(InputError, match=r"line 3: id 'a' is already used \(line 2\)"):
        read_manifest(m)
    m.write_text("id,body,pattern,strokes\na,default,p.json\n")
    with pytest.raises(InputError, match="line 2: 3 cells, the header names 4 columns"):
        read_manifest(m)
    m.write_text("id,body,pattern,strokes\n\n")
    with pytest.raises(InputError, match="lists no jobs"):
        read_manifest(m)
    with pytest.raises(InputError, match="job 2: expected an object"):
        read_manifest(_json(tmp_path, [ROW, ["a"]]))
    with pytest.raises(InputError, match="job 1: unknown key 'colour'"):
        read_manifest(_json(tmp_path, [{**ROW, "colour": "red"}]))
    with pytest.raises(InputError, match="expected a list of jobs"):
        read_manifest(_json(tmp_path, {"jobs": 3}))
    with pytest.raises(InputError, match="manifest not found"):
        read_manifest(tmp_path / "missing.csv")


def test_cli_bad_manifest_exit_2_one_line_nothing_written(tmp_path, run_cli):
    m = write_csv(tmp_path / "jobs.csv", [{**ROW, "edge_length": "-1"}])
    out = tmp_path / "out"
    r = run_cli("batch", "dress", m, "-o", out, "--local")
    assert r.code == 2 and r.err.count("\n") == 1 and "Traceback" not in r.err
    assert r.err.startswith(f"kitsuke: error: {m}: line 2: edge_length must be between")
    assert not out.exists()


def test_cli_refuses_a_used_folder_without_resume(tmp_path, run_cli):
    m = write_csv(tmp_path / "jobs.csv", [ROW])
    out = tmp_path / "out"
    out.mkdir()
    (out / "mine.txt").write_text("keep")
    r = run_cli("batch", "dress", m, "-o", out, "--local")
    assert r.code == 2 and "is not empty: --resume finishes the batch written there" in r.err
    assert [p.name for p in out.iterdir()] == ["mine.txt"]
    r = run_cli("batch", "dress", m, "-o", out, "--local", "--retry-failed")
    assert r.code == 2 and "--retry-failed goes with --resume" in r.err
    r = run_cli("batch", "dress", m, "-o", out, "--local", "--workers", "0")
    assert r.code == 2 and "--workers must be at least 1" in r.err


def test_cli_without_ray_says_how_to_install_it(tmp_path, run_cli, monkeypatch):
    monkeypatch.setitem(sys.modules, "ray", None)  # `import ray` raises ImportError, as without the extra
    m = write_csv(tmp_path / "jobs.csv", [ROW])
    r = run_cli("batch", "dress", m, "-o", tmp_path / "out")
    assert r.code == 2 and r.err.count("\n") == 1
    assert "pip install 'kitsuke[batch]'" in r.err and "--local" in r.err
    assert not (tmp_path / "out").exists()
