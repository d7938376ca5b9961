"""Temporal filter for joint positions: the One-Euro filter (Casiez, Roussel & Vogel, CHI 2012).

Each coordinate of each joint is filtered on its own (vectorised over joints and coordinates; a loop over
frames, which the filter's recursion needs). The cut-off frequency rises with speed, so slow motion is smoothed
hard (jitter goes) and fast motion little (no lag):
    cutoff = min_cutoff + beta·|ẋ|,   alpha(f_c, dt) = 1 / (1 + 1 / (2π f_c dt)),
with ẋ the derivative smoothed at d_cutoff. dt comes from the frames' own times, so invalid frames (no person)
are skipped cleanly: they stay invalid and the next valid frame continues the filter with the real time gap,
which lets it follow the new position almost at once after a long gap.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ._sequence import PoseSequence


@dataclass(frozen=True)
class OneEuroConfig:
    """Parameters of the One-Euro filter.

    Attributes
    ----------
    min_cutoff_hz : cut-off frequency at rest, Hz (lower: smoother when still).
    beta : increase of the cut-off with speed, Hz per (m/s) (higher: less lag when moving fast).
    d_cutoff_hz : cut-off frequency of the speed estimate, Hz.
    enabled : False passes positions through unchanged.
    """

    min_cutoff_hz: float = 1.0
    beta: float = 2.0
    d_cutoff_hz: float = 1.0
    enabled: bool = True

    def __post_init__(self) -> None:
        for name in ("min_cutoff_hz", "d_cutoff_hz"):
            v = getattr(self, name)
            if not (v > 0 and math.isfinite(v)):
                raise ValueError(f"{name} must be a positive number of Hz, got {v}")
        if not (self.beta >= 0 and math.isfinite(self.beta)):
            raise ValueError(f"beta must be a non-negative number, got {self.beta}")


def _alpha(cutoff_hz: np.ndarray | float, dt: float) -> np.ndarray | float:
    return 1.0 / (1.0 + 1.0 / (2.0 * math.pi * cutoff_hz * dt))


class OneEuroFilter:
    """The One-Euro filter fed one sample at a time (a live camera); `one_euro` runs it over a whole signal.

    f = OneEuroFilter(OneEuroConfig()); smoothed = f(x, t)   # x: array of any shape, t: seconds (non-decreasing)
    """

    def __init__(self, config: OneEuroConfig | None = None) -> None:
        self.config = config or OneEuroConfig()
        self.reset()

    def reset(self) -> None:
        """Forget the past: the next sample passes through (a new person, a new clip)."""
        self._x: np.ndarray | None = None
        self._dx: np.ndarray | None = None
        self._t = 0.0

    def __call__(self, x: np.ndarray, t: float) -> np.ndarray:
        """The filtered value of sample `x` at time `t` seconds (a new float64 array)."""
        x = np.array(x, dtype=np.float64, copy=True)
        cfg = self.config
        if not cfg.enabled:
            return x
        if self._x is None:
            self._x, self._dx, self._t = x.copy(), np.zeros_like(x), float(t)
            return x
        dt = float(t) - self._t
        if dt <= 0:  # repeated timestamp: keep the previous estimate's state, pass the value through smoothed
            dt = 1e-3
        a_d = _alpha(cfg.d_cutoff_hz, dt)
        dx = a_d * (x - self._x) / dt + (1.0 - a_d) * self._dx
        a = _alpha(cfg.min_cutoff_hz + cfg.beta * np.abs(dx), dt)
        x_hat = a * x + (1.0 - a) * self._x
        self._x, self._dx, self._t = x_hat, dx, float(t)
        return x_hat.copy()


def one_euro(values: np.ndarray, times: np.ndarray, valid: np.ndarray, config: OneEuroConfig) -> np.ndarray:
    """Filter a signal over time.

    Parameters
    ----------
    values : (n, ...) float64, any units (joint positions: metres).
    times : (n,) float64 seconds, non-decreasing.
    valid : (n,) bool; invalid frames are passed through untouched and skipped by the filter.

    Returns
    -------
    (n, ...) float64 filtered values (a new array).
    """
    out = np.array(values, dtype=np.float64, copy=True)
    f = OneEuroFilter(config)
    for i in np.flatnonzero(valid):
        out[i] = f(out[i], times[i])
    return out


def filter_poses(poses: PoseSequence, config: OneEuroConfig | None = None) -> PoseSequence:
    """A copy of the sequence with its positions One-Euro filtered (image points are left as detected).

    The pelvis-relative structure is filtered as positions; bone lengths change slightly (the filter is per
    coordinate), which is fine upstream of the posture correction: the correction keeps whatever lengths it gets.
    """
    cfg = config or OneEuroConfig()
    filtered = one_euro(poses.positions, poses.times, poses.valid, cfg)
    src = dict(poses.source)
    if cfg.enabled:
        src["filter"] = {
            "kind": "one-euro",
            "min_cutoff_hz": cfg.min_cutoff_hz,
            "beta": cfg.beta,
            "d_cutoff_hz": cfg.d_cutoff_hz,
        }
    return replace(poses.copy(), positions=filtered, source=src)
