"""`kitsuke pattern ...` end to end, in-process (and one real subprocess run)."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from .conftest import HOODY, SHIRT, TEAGAN, two_squares


def test_convert_between_formats(run_cli, tmp_path):
    out = tmp_path / "shirt.json"
    r = run_cli("pattern", "convert", SHIRT, out)
    assert r.code == 0 and r.err == ""
    data = json.loads(out.read_text())
    assert data["format"] == "kitsuke.pattern" and len(data["pieces"]) == 8 and len(data["seams"]) == 18
    r = run_cli("pattern", "convert", out, tmp_path / "shirt.svg")
    assert r.code == 0 and (tmp_path / "shirt.svg").read_text().startswith("<?xml")
    r = run_cli("pattern", "convert", TEAGAN, tmp_path / "teagan.png", "--max-px", "400")
    assert r.code == 0 and (tmp_path / "teagan.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_info_and_validate(run_cli, tmp_path):
    r = run_cli("pattern", "info", HOODY)
    info = json.loads(r.out)
    assert r.code == 0 and len(info["pieces"]) == 6 and len(info["seams"]) == 12 and info["warnings"] == []
    mismatch = tmp_path / "mismatch.json"
    mismatch.write_text(json.dumps(two_squares(b={"piece": "right", "edge": 0})))
    r = run_cli("pattern", "validate", mismatch)
    assert r.code == 0 and "1 warning" in r.out and "warning: seam 0" in r.err


def test_kimono_and_mesh(run_cli, tmp_path):
    k = tmp_path / "kimono.json"
    r = run_cli("pattern", "kimono", "--yuki", "66", "--shoulder", "32", "-o", k)
    assert r.code == 0 and "kimono 158/66/32/49" in r.out
    sizes = json.loads(k.read_text())["meta"]["kimono"]["size"]
    assert sizes["sleeve_width"] == 34.0
    obj = tmp_path / "kimono.obj"
    r = run_cli("pattern", "mesh", k, "-o", obj, "--edge-length", "3")
    summary = json.loads(r.out)
    assert r.code == 0 and summary["seams"] == 21 and summary["quality"]["min_angle_away_deg"] >= 25
    assert obj.read_text().count("\nf ") == summary["faces"]
    square = tmp_path / "square.json"
    assert run_cli("pattern", "kimono", "--sleeve-round", "0", "-o", square).code == 0
    assert len(json.loads(square.read_text())["seams"]) == 19  # no rounded sleeve corners to sew
    r = run_cli("pattern", "texture", "-o", tmp_path / "tile.png", "--px-per-cm", "10")
    assert r.code == 0 and json.loads(r.out)["tile_cm"][0] == 3.0


@pytest.mark.parametrize(
    ("args", "names"),
    [
        (["pattern", "convert", "{bad}", "{out}"], "{bad}"),
        (["pattern", "info", "{bad}"], "{bad}"),
        (["pattern", "validate", "{bad}"], "{bad}"),
        (["pattern", "mesh", "{bad}", "-o", "{tmp}/m.obj"], "{bad}"),
        (["pattern", "convert", "{good}", "{good}"], "{good}"),  # an input is never overwritten
        (["pattern", "convert", "{good}", "{tmp}/x.obj"], "x.obj"),
        (["pattern", "kimono", "--yuki", "20", "-o", "{out}"], "--yuki"),
        (["pattern", "kimono", "--sleeve-round", "-1", "-o", "{out}"], "--sleeve-round"),
        (["pattern", "kimono", "--bolt-width", "30", "-o", "{out}"], "--sleeve-width"),
        (["pattern", "mesh", "{good}", "-o", "{tmp}/m.obj", "--edge-length", "-1"], "--edge-length"),
    ],
)
def test_bad_input_exit_2_one_line(run_cli, tmp_path, args, names):
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(two_squares(b={"piece": "ghost", "edge": 0})))
    good = tmp_path / "good.json"
    good.write_text(json.dumps(two_squares()))
    before = good.read_text()
    out = tmp_path / "out.json"
    fill = {"bad": bad, "good": good, "out": out, "tmp": tmp_path}
    r = run_cli(*[a.format(**fill) for a in args])
    assert r.code == 2
    assert r.err.count("\n") == 1 and r.err.startswith("kitsuke: error: ")
    assert names.format(**fill) in r.err and "Traceback" not in r.err
    assert not out.exists() and not (tmp_path / "m.obj").exists()
    assert good.read_text() == before
    assert not list(tmp_path.glob(".*.tmp"))  # no half-written temporary left behind


def test_subprocess_run(tmp_path, run_cli):
    out = tmp_path / "hoody.png"
    r = subprocess.run(
        [sys.executable, "-m", "kitsuke", "pattern", "convert", str(HOODY), str(out), "--max-px", "300"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert r.returncode == 0, r.stderr
    assert out.stat().st_size > 5000
    r = subprocess.run(
        [sys.executable, "-m", "kitsuke", "pattern", "info", str(tmp_path / "missing.json")],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert r.returncode == 2 and r.stderr.strip().endswith("pattern file not found") and "missing.json" in r.stderr
    # The program ends without the interpreter's teardown (`kitsuke.cli.run`): what it printed to a pipe arrives
    # whole, as the same call prints it in-process.
    r = subprocess.run(
        [sys.executable, "-m", "kitsuke", "pattern", "info", str(HOODY)], capture_output=True, text=True, timeout=120
    )
    inproc = run_cli("pattern", "info", HOODY)
    assert r.returncode == inproc.code == 0 and r.stdout == inproc.out and len(r.stdout) > 200
    # Its reader gone (`kitsuke pattern info P | head`): no message, the status of a process SIGPIPE ended.
    p = subprocess.Popen(
        [sys.executable, "-m", "kitsuke", "pattern", "info", str(HOODY)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    p.stdout.close()
    assert p.wait(timeout=120) == 141 and p.stderr.read() == ""


def test_kimono_fit_height_gives_the_default_kimono(run_cli, tmp_path):
    from kitsuke.pattern import default_kimono, load_pattern

    r = run_cli("pattern", "kimono", "--fit-height", "1.666", "-o", tmp_path / "k.json")
    assert r.code == 0, r.err
    got = load_pattern(tmp_path / "k.json")
    assert got.meta["kimono"]["size"] == default_kimono().meta["kimono"]["size"]
    bad = run_cli("pattern", "kimono", "--fit-height", "0.2", "-o", tmp_path / "k2.json")
    assert bad.code == 2 and "--fit-height" in bad.err and not (tmp_path / "k2.json").exists()
