"""Resource limits: refused before the work in one line naming the limit and how to raise it; raised from the
command line, the environment or Python."""

from __future__ import annotations

import pytest

from kitsuke import limits
from kitsuke.errors import InputError
from kitsuke.pattern import default_kimono, mesh_pattern

from .conftest import DATA

SHIRT = DATA / "pattern" / "shirt_mean_specification.json"


def test_meshing_past_the_triangle_limit_is_refused_and_can_be_raised():
    pattern = default_kimono()
    with limits.raised(triangles=1000), pytest.raises(InputError, match=r"--limit triangles=N"):
        mesh_pattern(pattern)
    with limits.raised(triangles=1000, pieces=1000):
        mesh_pattern(pattern, edge_length=20.0)  # coarse enough to fit


def test_cli_limit_anywhere_environment_and_bad_values(tmp_path, run_cli, monkeypatch):
    out = tmp_path / "shirt.obj"
    r = run_cli("pattern", "mesh", SHIRT, "-o", out, "--limit", "triangles=500")
    assert r.code == 2 and "over the limit of 500" in r.err and "KITSUKE_LIMIT_TRIANGLES" in r.err
    assert r.err.count("\n") == 1 and not out.exists()
    r = run_cli("--limit", "triangles=5e6", "pattern", "mesh", SHIRT, "-o", out)
    assert r.code == 0, r.err
    monkeypatch.setenv("KITSUKE_LIMIT_FILE_MB", "0.001")  # the shirt is 20 kB
    r = run_cli("pattern", "validate", SHIRT)
    assert r.code == 2 and "over the limit of 0.001 MB" in r.err
    monkeypatch.delenv("KITSUKE_LIMIT_FILE_MB")
    for bad, message in (("nope=3", "unknown limit"), ("triangles=-1", "positive"), ("triangles", "NAME=VALUE")):
        r = run_cli("pattern", "validate", SHIRT, "--limit", bad)
        assert r.code == 2 and message in r.err and r.err.count("\n") == 1, r.err
    monkeypatch.setenv("KITSUKE_LIMIT_FRAMES", "many")
    r = run_cli("pattern", "validate", SHIRT)
    assert r.code == 2 and "KITSUKE_LIMIT_FRAMES" in r.err
