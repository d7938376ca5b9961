"""Shared test helpers: the in-repo data folder, an in-process CLI runner and the Khronos glTF validator."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
from dataclasses import dataclass
from pathlib import Path

import pytest

DATA = Path(__file__).parent / "data"
ROOT = Path(__file__).resolve().parent.parent
#: The Khronos glTF validator, as `.ci/run` installs it (npm gltf-validator under .ci/node).
GLTF_VALIDATOR = ROOT / ".ci" / "node" / "node_modules" / "gltf-validator"
needs_gltf_validator = pytest.mark.skipif(
    not GLTF_VALIDATOR.exists() or shutil.which("node") is None, reason="gltf-validator not installed"
)


def gltf_report(path: Path) -> dict:
    """The Khronos validator's summary of a .glb file: {"errors", "warnings", "messages"}."""
    env = {**os.environ, "NODE_PATH": str(GLTF_VALIDATOR.parent)}
    script = ROOT / "tests" / "tools" / "validate_gltf.js"
    r = subprocess.run(["node", str(script), str(path)], capture_output=True, text=True, env=env, check=True)
    return json.loads(r.stdout)


@dataclass
class CliResult:
    code: int
    out: str
    err: str


@pytest.fixture
def run_cli(capsys):
    """Run `kitsuke ARGS...` in-process; returns exit code, stdout and stderr."""
    from kitsuke.cli import main

    def run(*args: str) -> CliResult:
        capsys.readouterr()
        try:
            code = main([str(a) for a in args])
        except SystemExit as e:  # argparse exits on usage errors and --help
            code = int(e.code or 0)
        captured = capsys.readouterr()
        return CliResult(code, captured.out, captured.err)

    return run


_exit_status: list[int] = []


def pytest_sessionfinish(session, exitstatus):  # noqa: ANN001
    _exit_status.append(int(exitstatus))


@pytest.hookimpl(trylast=True)
def pytest_unconfigure(config):  # noqa: ANN001
    """End the test process once pytest is done, with pytest's own status, without the interpreter's shutdown.

    Why: the suite leaves native libraries loaded (numba, libigl, OpenGL, Qt) whose teardown at interpreter exit
    is out of our hands, and one CI run in four ended "Exception ignored in: <stdout> ... TypeError" after every
    test had passed: Python then exits 120 and CI fails. The results are all written by now (pytest_unconfigure
    runs last), so the process flushes its streams and leaves."""
    import os
    import sys

    if not _exit_status or os.environ.get("KITSUKE_TEST_NORMAL_EXIT"):
        return
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except Exception:  # noqa: BLE001 - a closed or blocked pipe: nothing more can be said on it
            pass
    os._exit(_exit_status[0])
