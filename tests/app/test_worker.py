"""The app's wrap process: stages reported as they start, errors carried back as the library raises them, and
Cancel ending a wrap at once with the worker ready for the next."""

from __future__ import annotations

import threading
import time
from dataclasses import replace

import numpy as np
import pytest

from kitsuke.app import Cancelled, DressingSession, PatternEditor, WrapWorker
from kitsuke.body import default_body
from kitsuke.dressing.options import DressOptions
from kitsuke.errors import InputError
from kitsuke.geometry.surface import Surface
from kitsuke.pattern import Pattern
from kitsuke.pattern._types import EdgeRef


@pytest.fixture(scope="module")
def skirt_job():
    """A skirt from two rectangles, with a stroke on each round the waist (front and back)."""
    body = default_body()
    ed = PatternEditor(Pattern("skirt"))
    front = ed.add_piece([[0, 0], [60, 0], [60, 55], [0, 55]])
    back = ed.duplicate(front)
    ed.sew(EdgeRef(front, 1), EdgeRef(back, 3))
    ed.sew(EdgeRef(front, 3), EdgeRef(back, 1))
    s = DressingSession(body, ed.pattern)
    surface = Surface(body.mesh)
    for piece, z in ((front, 1), (back, -1)):
        s.draw_pattern_stroke(piece, np.array([[15.0, 45.0], [45.0, 45.0]]))
        xs = np.linspace(-0.12 * z, 0.12 * z, 5)
        s.draw_body_stroke(
            surface.cast(np.c_[xs, np.full(5, 0.95), np.full(5, 2.0 * z)], np.tile([0, 0, -z], (5, 1))).points
        )
    params = DressOptions().wrap_params(body, ed.pattern)
    return body, ed.pattern, s.wrap_strokes(), params


def test_worker_wraps_reports_stages_and_cancels(skirt_job):
    body, pattern, strokes, params = skirt_job
    worker = WrapWorker()
    try:
        stages: list[str] = []
        g = worker.wrap(body, pattern, strokes, params, progress=stages.append)
        assert g.n_vertices > 100 and np.isfinite(g.positions).all()
        assert stages[:3] == ["meshing", "resolving the strokes", "placing the pieces"]
        assert stages[-1] == "polishing"
        assert {"growing the cloth", "closing the seams", "settling", "restoring lengths"} <= set(stages)

        p0 = strokes.pairs[0]
        moved = replace(p0, pattern=replace(p0.pattern, piece="no_such_piece"))
        bad = replace(strokes, pairs=[moved, *strokes.pairs[1:]])
        with pytest.raises(InputError, match="no_such_piece"):  # the library's own error, carried back
            worker.wrap(body, pattern, bad, params)

        cancel = threading.Event()
        started = threading.Event()
        outcome: list = []

        def run() -> None:
            try:
                worker.wrap(body, pattern, strokes, params, cancel=cancel, progress=lambda _s: started.set())
                outcome.append("finished")
            except Cancelled:
                outcome.append("cancelled")

        t = threading.Thread(target=run)
        t.start()
        assert started.wait(60)
        t0 = time.monotonic()
        cancel.set()
        t.join(30)
        assert outcome == ["cancelled"] and time.monotonic() - t0 < 2.0
        assert worker.wrap(body, pattern, strokes, params).n_vertices == g.n_vertices  # a fresh child, same result
    finally:
        worker.close()
