"""Where a tab's camera stands: the body and the pattern board framed whole in the part of the canvas that the
control panel leaves free, whatever the window's size (a fixed camera put the board under the panel in a window
960 pixels wide, and most of it in a portrait one).

    framing = frame(low, high, fov_y, width_px, height_px)   # Framing(position, look_at), metres
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Pixels the control panel covers at the canvas's right: viser's "medium" panel (20 em of 16 px) and its gap from
#: the window's edge.
PANEL_PX = 20 * 16 + 16
#: Share of the free canvas left empty round the scene, on each side.
MARGIN = 0.04
#: Where the panel would leave less than this share of the canvas free, the whole canvas is framed: the scene
#: squeezed into a strip would be too small to draw on, and the panel can be collapsed.
MIN_FREE = 0.5


@dataclass(frozen=True)
class Framing:
    """A camera looking along -Z (at the body's front). position, look_at : (3,) float64, metres."""

    position: np.ndarray
    look_at: np.ndarray


def frame(
    low: np.ndarray, high: np.ndarray, fov_y: float, width_px: int, height_px: int, covered_px: int = PANEL_PX
) -> Framing:
    """The camera that shows the box [low, high] ((3,) metres each) whole, as large as fits, in the canvas's part
    left of the `covered_px` pixels at its right (all of it where that leaves less than MIN_FREE of its width),
    MARGIN of that part left round it. fov_y : the camera's vertical field of view, radians. width_px, height_px :
    the canvas, pixels. The box's front face (z = high[2]) is what must fit; the look-at point, round which the
    camera orbits, is on the view's axis at the box's middle depth."""
    low, high = np.asarray(low, dtype=np.float64), np.asarray(high, dtype=np.float64)
    if not (width_px > 0 and height_px > 0 and 0 < fov_y < np.pi and np.all(high >= low)):
        raise ValueError("frame needs a canvas of positive size, 0 < fov_y < pi and low <= high")
    free = width_px - covered_px if width_px - covered_px >= MIN_FREE * width_px else width_px
    tan_y = np.tan(fov_y / 2)
    tan_x = tan_y * width_px / height_px
    fill = 1.0 - 2.0 * MARGIN
    half, middle = (high - low) / 2, (high + low) / 2
    # Distance from the front face at which the box's height fills `fill` of the canvas's, and its width `fill`
    # of the free part's (free / width_px of the canvas's width).
    distance = max(half[1] / (tan_y * fill), half[0] / (tan_x * fill * free / width_px), 1e-3)
    # The free part's middle is at x = free / width_px - 1 in normalised device coordinates (-1 at the left).
    x = middle[0] - (free / width_px - 1.0) * distance * tan_x
    position = np.array([x, middle[1], high[2] + distance])
    return Framing(position, np.array([x, middle[1], middle[2]]))
