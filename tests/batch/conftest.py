"""Shared by the batch tests: the shipped files a manifest points at, a manifest writer, and one local Ray for the
whole session (2 CPUs), started only by the tests that use Ray and skipped where Ray is not installed."""

from __future__ import annotations

import csv
import logging
from pathlib import Path

import pytest

from ..conftest import DATA

ROOT = DATA.parent.parent
STROKES = ROOT / "src" / "kitsuke" / "assets" / "strokes"
MEAN_ALL = DATA / "bodies" / "mean_all.obj"
PATTERNS = DATA / "pattern"


def write_csv(path: Path, rows: list[dict]) -> Path:
    """A CSV manifest with the union of the rows' columns (missing cells empty)."""
    columns = list(dict.fromkeys(k for r in rows for k in r))
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=columns)
        w.writeheader()
        w.writerows(rows)
    return path


@pytest.fixture(scope="session")
def ray_session():
    ray = pytest.importorskip("ray", reason="Ray is not installed (pip install 'kitsuke[batch]')")
    started = not ray.is_initialized()
    if started:
        ray.init(
            address="local", num_cpus=2, include_dashboard=False, log_to_driver=False, logging_level=logging.WARNING
        )
    yield ray
    if started:
        ray.shutdown()


@pytest.fixture(params=["local", pytest.param("ray", marks=pytest.mark.slow)])
def runner_kind(request):
    """Each runner in turn: "local" or "ray" (the session's Ray started for it: seconds, so marked slow)."""
    if request.param == "ray":
        request.getfixturevalue("ray_session")
    return request.param


def make_runner(kind: str, **kwargs):
    from kitsuke.batch import LocalRunner, RayRunner

    return LocalRunner(**kwargs) if kind == "local" else RayRunner(**kwargs)
