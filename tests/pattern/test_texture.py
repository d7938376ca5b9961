"""Procedural textile textures: seamless tiles, region rendering consistent with the tile, anti-aliasing."""

from __future__ import annotations

import numpy as np
import pytest

from kitsuke.errors import InputError
from kitsuke.pattern import PALETTES, kimono_texture, texture_tile_size_cm, texture_uv


@pytest.mark.parametrize("motif", ["asanoha", "seigaiha"])
def test_tile_is_seamless_and_matches_regions(motif):
    repeat = 3.0
    tw, th = texture_tile_size_cm(motif, repeat)
    ppc = 20.0
    # A region two tiles wide, rendered directly, repeats with the tile's period (in whole pixels here).
    region = kimono_texture(motif=motif, repeat_cm=repeat, px_per_cm=ppc, size_cm=(2 * tw, th))
    w = round(tw * ppc)
    if abs(tw * ppc - w) < 1e-9:
        diff = np.abs(region[:, :w].astype(int) - region[:, w : 2 * w].astype(int))
        assert diff.max() <= 1
    tile = kimono_texture(motif=motif, repeat_cm=repeat, px_per_cm=ppc)
    # Wrapping the tile: the last column continues into the first (as much as neighbouring columns differ).
    t = tile.astype(int)
    wrap = np.abs(t[:, -1] - t[:, 0]).mean()
    inner = np.abs(np.diff(t, axis=1)).mean()
    assert wrap <= 2.5 * inner
    wrap_v = np.abs(t[-1] - t[0]).mean()
    assert wrap_v <= 2.5 * np.abs(np.diff(t, axis=0)).mean()


def test_colours_and_antialiasing():
    img = kimono_texture(motif="asanoha", repeat_cm=3.0, px_per_cm=30.0, size_cm=(12, 12), palette="indigo")
    ground, ink = (np.array(c) for c in PALETTES["indigo"])
    px = img.reshape(-1, 3).astype(float)
    d_ground = np.linalg.norm(px - ground, axis=1)
    d_ink = np.linalg.norm(px - ink, axis=1)
    assert 0.5 < np.mean(d_ground < 2) < 0.95  # mostly ground
    assert 0.03 < np.mean(d_ink < 2) < 0.4  # clear ink lines
    between = (d_ground > 10) & (d_ink > 10)
    assert 0.005 < between.mean() < 0.25  # anti-aliased edges, not a blur


def test_uv_maps_the_tile_size():
    tw, th = texture_tile_size_cm("asanoha", 3.0)
    assert (tw, th) == pytest.approx((3.0, 3.0 * np.sqrt(3)))
    np.testing.assert_allclose(texture_uv([[3.0, 0.0], [6.0, th]], "asanoha", 3.0), [[1, 0], [2, 1]])


@pytest.mark.parametrize(
    "kwargs", [{"motif": "paisley"}, {"repeat_cm": 0}, {"palette": "neon"}, {"size_cm": (0, 5)}, {"px_per_cm": -1}]
)
def test_bad_texture_arguments(kwargs):
    with pytest.raises(InputError):
        kimono_texture(**kwargs)
