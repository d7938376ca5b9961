"""The tab's camera frames the body and the pattern board whole beside the control panel (`kitsuke.app.framing`),
whatever the window's size."""

from __future__ import annotations

import numpy as np
import pytest

from kitsuke.app.framing import MARGIN, MIN_FREE, PANEL_PX, frame

LOW, HIGH = np.array([-0.85, 0.0, -0.15]), np.array([2.15, 1.86, 0.2])  # the default body and the kimono's board


def _pixels(f, points, fov_y, w, h):
    """(n, 2) pixels of world points seen by the framing's camera (looking along -Z)."""
    rel = points - f.position
    depth = -rel[:, 2]
    t = np.tan(fov_y / 2)
    return np.c_[(rel[:, 0] / (depth * t * w / h) + 1) / 2 * w, (1 - rel[:, 1] / (depth * t)) / 2 * h]


def _front_corners(low, high):
    return np.array([[x, y, high[2]] for x in (low[0], high[0]) for y in (low[1], high[1])])


@pytest.mark.parametrize("size", [(960, 600), (1120, 700), (1280, 800), (1920, 1080), (700, 900), (500, 800)])
def test_the_scene_fills_the_canvas_left_of_the_panel(size):
    w, h = size
    fov = np.radians(40.0)
    f = frame(LOW, HIGH, fov, w, h)
    assert np.allclose(f.position[:2], f.look_at[:2]) and f.position[2] > f.look_at[2]  # looking along -Z
    free = w - PANEL_PX if w - PANEL_PX >= MIN_FREE * w else w
    px = _pixels(f, _front_corners(LOW, HIGH), fov, w, h)
    left, right = MARGIN * free, (1 - MARGIN) * free
    top, bottom = MARGIN * h, (1 - MARGIN) * h
    tol = 1e-6 * w
    assert px[:, 0].min() >= left - tol and px[:, 0].max() <= right + tol
    assert px[:, 1].min() >= top - tol and px[:, 1].max() <= bottom + tol
    # as large as fits: it touches the margins on one axis, and is centred on both
    assert np.isclose(px[:, 0].min(), left, atol=1.0) or np.isclose(px[:, 1].min(), top, atol=1.0)
    assert np.isclose(px[:, 0].min() + px[:, 0].max(), free) and np.isclose(px[:, 1].min() + px[:, 1].max(), h)
    # the box's back face lies within a pixel of what its front face spans (farther, it looks smaller)
    back = _pixels(f, _front_corners(LOW, HIGH) - [0, 0, HIGH[2] - LOW[2]], fov, w, h)
    assert back[:, 0].min() >= px[:, 0].min() - 1 and back[:, 0].max() <= px[:, 0].max() + 1
    assert back[:, 1].min() >= px[:, 1].min() - 1 and back[:, 1].max() <= px[:, 1].max() + 1


def test_a_window_the_panel_would_mostly_cover_is_framed_whole():
    """At 500 px wide the panel leaves 164 px: the scene fills the canvas instead (the panel can be collapsed)."""
    fov = np.radians(40.0)
    px = _pixels(frame(LOW, HIGH, fov, 500, 800), _front_corners(LOW, HIGH), fov, 500, 800)
    assert px[:, 0].max() > 500 - PANEL_PX


def test_bad_canvas_is_refused():
    with pytest.raises(ValueError, match="positive size"):
        frame(LOW, HIGH, np.radians(40.0), 0, 600)
