"""One-Euro filter: smooths jitter, follows fast motion, skips invalid frames, switches off."""

from __future__ import annotations

import numpy as np
import pytest

from kitsuke.pose import OneEuroConfig, PoseSequence, filter_poses, one_euro


def test_reduces_jitter_on_a_still_signal():
    rng = np.random.default_rng(1)
    t = np.arange(300) / 30.0
    x = 0.5 + rng.normal(0, 0.01, (300, 23, 3))
    y = one_euro(x, t, np.ones(300, bool), OneEuroConfig())
    # after the first second the noise (1 cm) is cut about 3 times (2.97 measured), and the mean stays put
    assert y[30:].std() < x[30:].std() / 2.5
    assert abs(y[30:].mean() - 0.5) < 2e-3


def test_follows_fast_motion_with_little_lag():
    t = np.arange(120) / 60.0
    x = np.zeros((120, 1, 1))
    x[:, 0, 0] = 2.0 * t  # 2 m/s, a fast kick
    y = one_euro(x, t, np.ones(120, bool), OneEuroConfig())
    lag = (x - y)[60:, 0, 0]
    assert lag.max() < 0.05  # 3.5 cm measured: 17 ms behind at 2 m/s
    slow = one_euro(x, t, np.ones(120, bool), OneEuroConfig(beta=0.0))
    assert (x - slow)[60:, 0, 0].max() > 2 * lag.max()  # beta is what removes the lag


def test_invalid_frames_are_skipped_cleanly():
    t = np.arange(10) / 10.0
    x = np.ones((10, 2, 3))
    x[5:] = 2.0
    valid = np.ones(10, bool)
    valid[3:5] = False
    x[3:5] = np.nan
    y = one_euro(x, t, valid, OneEuroConfig())
    assert np.isnan(y[3:5]).all() and np.isfinite(y[valid]).all()
    assert (y[5:] > 1.0).all()  # continues across the gap toward the new position


def test_switch_off_and_sequence_wrapper():
    rng = np.random.default_rng(2)
    pos = rng.normal(0, 1, (5, 23, 3))
    s = PoseSequence(positions=pos, valid=np.ones(5, bool), times=np.arange(5) / 30, fps=30)
    assert np.array_equal(filter_poses(s, OneEuroConfig(enabled=False)).positions, pos)
    f = filter_poses(s)
    assert f.source["filter"]["kind"] == "one-euro" and not np.array_equal(f.positions, pos)
    assert np.array_equal(s.positions, pos)  # input untouched


def test_bad_config():
    with pytest.raises(ValueError):
        OneEuroConfig(min_cutoff_hz=0)
    with pytest.raises(ValueError):
        OneEuroConfig(beta=-1)


def test_online_filter_equals_the_whole_signal():
    """Fed one sample at a time (a live camera), the filter gives exactly what the whole-signal filter gives."""
    from kitsuke.pose import OneEuroConfig, OneEuroFilter, one_euro

    rng = np.random.default_rng(3)
    times = np.cumsum(rng.uniform(0.02, 0.05, 80))
    values = np.cumsum(rng.normal(0, 0.01, (80, 23, 3)), axis=0)
    valid = rng.random(80) > 0.1
    cfg = OneEuroConfig(min_cutoff_hz=1.5, beta=3.0)
    whole = one_euro(values, times, valid, cfg)
    live = OneEuroFilter(cfg)
    for i in np.flatnonzero(valid):
        np.testing.assert_array_equal(live(values[i], times[i]), whole[i])
    assert not np.allclose(whole[valid], values[valid])  # it does filter
