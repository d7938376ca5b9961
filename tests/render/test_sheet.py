"""Contact sheets: layout, labels, and several views of one scene."""

from __future__ import annotations

import numpy as np
import pytest

from kitsuke.errors import InputError
from kitsuke.render import contact_sheet, render_sheet, render_views

from .shapes import box, mask_bbox, subject_mask


def _panel(value: int, h: int = 100, w: int = 80) -> np.ndarray:
    return np.full((h, w, 3), value, np.uint8)


def test_layout_and_labels():
    images = [_panel(10), _panel(60), _panel(110)]
    sheet = contact_sheet(images, ["front", "side", "back"], background="white", label_color="black")
    label_h = 18  # max(18, 4.5% of 100)
    assert sheet.shape == (100 + label_h, 240, 3)
    for i, value in enumerate((10, 60, 110)):
        assert np.all(sheet[:100, i * 80 : (i + 1) * 80] == value)
        strip = sheet[100:, i * 80 : (i + 1) * 80]
        dark = (strip < 128).all(axis=2)
        assert 10 < dark.sum() < 0.5 * dark.size  # the label text is there, and is text (not a fill)
        cols = np.nonzero(dark.any(axis=0))[0]
        assert abs((cols.min() + cols.max()) / 2 - 40) < 6  # centred under its panel


def test_grid_padding_and_rgba():
    rgba = np.zeros((50, 40, 4), np.uint8)  # fully transparent: shows the sheet background
    sheet = contact_sheet([rgba] * 5, None, columns=2, padding=4, background="#808080")
    assert sheet.shape == (3 * 50 + 4 * 4, 2 * 40 + 3 * 4, 3)
    assert np.all(sheet == 0x80)


def test_bad_sheets():
    with pytest.raises(InputError, match="no images"):
        contact_sheet([])
    with pytest.raises(InputError, match="differ in size"):
        contact_sheet([_panel(0), _panel(0, h=90)])
    with pytest.raises(InputError, match="2 labels for 1 images"):
        contact_sheet([_panel(0)], ["a", "b"])
    with pytest.raises(InputError, match="uint8"):
        contact_sheet([np.zeros((10, 10, 3), np.float32)])


def test_render_sheet_of_front_side_back(renderer):
    b = box()
    w, h = 120, 150
    views = render_views(b, ("front", "side", "back"), renderer=renderer, size=(w, h), background=None)
    cover = [subject_mask(v).mean() for v in views]
    assert cover[0] > 1.6 * cover[1] and cover[2] == pytest.approx(cover[0], abs=0.01)
    sheet = render_sheet(b, renderer=renderer, size=(w, h))
    assert sheet.shape[1] == 3 * w and sheet.shape[0] > h and sheet.dtype == np.uint8
    with pytest.raises(InputError, match="views"):
        render_views(b, view="front")


def test_views_share_one_scale(renderer):
    wide = box(1.6, 1.0, 0.2)  # framed by its width from the front, by its height from the side
    size = (120, 150)

    def heights(same_scale):
        views = render_views(
            wide,
            ("front", "side"),
            renderer=renderer,
            size=size,
            background=None,
            same_scale=same_scale,
            fov_y_deg=1.0,  # nearly orthographic: the near face of the box is not magnified
        )
        return [mask_bbox(subject_mask(v))[3] - mask_bbox(subject_mask(v))[1] + 1 for v in views]

    front, side = heights(True)
    assert abs(front - side) <= 2  # the same 1 m shows at the same size
    front, side = heights(False)
    assert side > 1.3 * front
