"""`kitsuke batch calibrate`: kimono calibrations from a manifest, each the table `kitsuke kimono calibrate` writes;
a pattern that is not a kimono refused by itself; bad manifests refused whole."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from kitsuke.batch import read_calibrate_manifest
from kitsuke.errors import InputError
from kitsuke.pose import read_constraints

DATA = Path(__file__).resolve().parents[1] / "data"


def test_calibrate_manifests_are_checked_whole(tmp_path):
    m = tmp_path / "k.csv"
    m.write_text("id,pattern,step\nstandard,default,15\nmine,kimono.json,45\n")
    jobs = read_calibrate_manifest(m)
    assert [j.id for j in jobs] == ["standard", "mine"] and jobs[0].pattern == "default"
    assert jobs[1].pattern == str(tmp_path / "kimono.json") and jobs[1].step_deg == 45.0
    for text, words in (
        ("id,pattern,step\na,default,7\n", "step must divide 180"),
        ("id,pattern,body\na,default,x\n", "unknown column 'body'"),
        ("id,step\na,15\n", "no 'pattern'"),
        ("id,pattern\na,default\na,default\n", "already used"),
    ):
        m.write_text(text)
        with pytest.raises(InputError, match=words):
            read_calibrate_manifest(m)


@pytest.mark.slow
def test_batch_calibrate_writes_tables_and_isolates_a_non_kimono(tmp_path, run_cli):
    manifest = tmp_path / "kimonos.csv"
    shirt = DATA / "pattern" / "shirt_mean_specification.json"
    manifest.write_text(f"id,pattern,step\nstandard,default,90\nshirt,{shirt},90\n")
    out = tmp_path / "out"
    r = run_cli("batch", "calibrate", manifest, "-o", out, "--local", "--workers", "2")
    assert r.code == 1 and "1 of 2 jobs gave no table" in r.err
    summary = json.loads((out / "summary.json").read_text())
    status = {j["id"]: j["status"] for j in summary["jobs"]}
    assert status == {"standard": "ok", "shirt": "refused"}
    table = read_constraints(out / "standard" / "constraints.json")
    assert table.source == "calibrated" and list(table.knee.theta_deg) == [0.0, 90.0]
    assert (out / "standard" / "e.png").stat().st_size > 20_000
    rows = (out / "summary.csv").read_text().splitlines()
    assert rows[0].startswith("id,status,reason,seconds") and "knee_e_min_cm" in rows[0]
    assert "not a kimono" in next(row for row in rows if row.startswith("shirt,"))
