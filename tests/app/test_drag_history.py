"""The app's drag history (no browser): pins and drags undo and redo one operation at a time, and what was done
replays from the recorded drags file to the same garment."""

from __future__ import annotations

import numpy as np
import pytest

from kitsuke.app.drag_history import DragHistory
from kitsuke.body import default_body
from kitsuke.cloth import BodyCollider
from kitsuke.dressing import apply_drags, drags_from_dict, drags_to_dict
from kitsuke.dressing.drag import DragSession
from tests.dressing.test_drag import front_of, skirt_garment


@pytest.fixture(scope="module")
def body():
    return default_body()


def test_pin_drag_undo_redo_and_replay(body):
    garment, _ = skirt_garment(body)
    collider = BodyCollider.from_body(body)
    h = DragHistory(DragSession(body, garment, collider=collider))
    x0 = h.session.positions.copy()
    back = int(np.argmin(x0[:, 2] - 0.1 * x0[:, 1]))  # a vertex low on the back
    assert h.toggle_pin(back) is True
    g = front_of(x0, 0.9)
    h.grab(x0[g])
    for dy in (0.02, 0.04):
        h.move(x0[g] + [0, dy, 0])  # projected onto the body, as the pointer's targets are
    h.release()
    after = h.session.positions.copy()
    assert after[g, 1] - x0[g, 1] > 0.02  # it moved up
    assert np.linalg.norm(after[back] - x0[back]) < 1e-9  # the pin held
    assert [s.pins is not None for s in h.steps] == [True, False] and len(h.steps[1].path) == 2

    # the file says what was done: replayed on the garment as it was, it gives the same garment
    drags = drags_from_dict(drags_to_dict(h.drags()))
    replay = DragSession(body, garment, collider=collider)
    apply_drags(replay, drags)
    assert np.abs(replay.positions - after).max() < 2e-3

    assert h.undo() and len(h.steps) == 1 and np.abs(h.session.positions - x0).max() < 1e-12  # the drag undone
    assert h.session.pinned[back]
    assert h.undo() and h.steps == [] and not h.session.pinned.any()  # and the pin
    assert not h.undo()
    assert h.redo() and h.redo() and not h.redo()
    np.testing.assert_allclose(h.session.positions, after)
    h.unpin_all()
    assert not h.session.pinned.any() and h.steps[-1].unpin == "all"
