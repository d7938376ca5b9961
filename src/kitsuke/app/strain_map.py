"""Strain as colours on the garment: the cloth's own colour where it is at rest, yellow at the quality target,
red at twice it and beyond (where a viewer should look)."""

from __future__ import annotations

import numpy as np

#: (strain as a multiple of the target, RGB): the ramp's stops.
STOPS = ((0.0, (70, 95, 160)), (0.5, (90, 170, 120)), (1.0, (240, 210, 40)), (2.0, (220, 40, 30)))


def strain_colors(strain: np.ndarray, target: float) -> np.ndarray:
    """(V, 3) uint8 colours of per-vertex strain (V,) (fractions) against `target` (a fraction, e.g. 0.05)."""
    x = np.asarray(strain, dtype=np.float64) / target
    at = np.array([s for s, _ in STOPS])
    rgb = np.array([c for _, c in STOPS], dtype=np.float64)
    return np.stack([np.interp(x, at, rgb[:, k]) for k in range(3)], axis=1).round().astype(np.uint8)
