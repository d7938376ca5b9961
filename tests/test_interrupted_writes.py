"""A `kitsuke dress` killed while it writes its outputs leaves the previous outputs as they were.

The child process holds every finished temporary file for a while before renaming it onto the output (os.replace
is wrapped to wait), so the signal lands mid-write for certain: after the GLB is written, before it replaces the
old one.
"""

from __future__ import annotations

import signal
import subprocess
import sys
import time

import pytest

from .conftest import DATA

pytestmark = pytest.mark.slow

ROOT = DATA.parent.parent
CHILD = """
import os, sys, time
from pathlib import Path
original = os.replace
def slow_replace(src, dst):
    # The marker appears whole (renamed into place): the parent may read it the moment it exists.
    Path(sys.argv[1] + ".part").write_text(str(src))
    original(sys.argv[1] + ".part", sys.argv[1])
    time.sleep(60)
    original(src, dst)
os.replace = slow_replace
from kitsuke.cli import main
sys.exit(main(sys.argv[2:]))
"""

OLD = b"the previous output\n"


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGKILL], ids=["SIGTERM", "SIGKILL"])
def test_killed_dress_keeps_previous_outputs(tmp_path, sig):
    outputs = {k: tmp_path / f"shirt.{k}" for k in ("glb", "obj", "json")}
    for p in outputs.values():
        p.write_bytes(OLD)
    marker = tmp_path / "replacing"
    args = [
        "dress",
        "--body",
        DATA / "bodies" / "mean_all.obj",
        "--pattern",
        DATA / "pattern" / "shirt_mean_specification.json",
        "--strokes",
        ROOT / "src" / "kitsuke" / "assets" / "strokes" / "shirt_mean_all.json",
        "-o",
        outputs["glb"],
        "--obj",
        outputs["obj"],
        "--report",
        outputs["json"],
    ]
    proc = subprocess.Popen(
        [sys.executable, "-c", CHILD, str(marker), *map(str, args)], stderr=subprocess.PIPE, text=True
    )
    try:
        deadline = time.monotonic() + 300
        while not marker.exists():
            assert proc.poll() is None, f"dress ended before writing: {proc.stderr.read()}"
            assert time.monotonic() < deadline, "dress did not reach its first write in 300 s"
            time.sleep(0.05)
        pending = marker.read_text()
        assert pending.startswith(str(tmp_path)) and pending.endswith(".tmp")
        proc.send_signal(sig)
        code = proc.wait(30)
        err = proc.stderr.read()
    finally:
        proc.kill()
    for p in outputs.values():
        assert p.read_bytes() == OLD, f"{p.name} changed"
    if sig == signal.SIGTERM:
        # Terminated cleanly: one line, exit 143, and the temporary file removed.
        assert code == 143, err
        assert err.strip().splitlines()[-1] == "kitsuke: terminated"
        assert sorted(p.name for p in tmp_path.iterdir()) == sorted([*(p.name for p in outputs.values()), "replacing"])
    else:
        assert code == -signal.SIGKILL
