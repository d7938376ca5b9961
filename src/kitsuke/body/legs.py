"""The gap between the legs of a standing body, and capsules that fill it.

A skirt grown over the hips (the wrap's growth, SPEC §4.2) continues down along its own surface; below the crotch
the collision pushes each vertex out of the nearest leg, and cloth near the inside of a thigh goes out on the
inside: the skirt wraps one leg and tears (measured on random GarmentCode skirts and dresses: edges at 5-9x their
length at knee height). With the gap filled for the wrap's shaping steps, the cloth drapes round both legs as a
skirt does; the settle then runs against the body alone.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..geometry import TriMesh


@dataclass(frozen=True)
class LegGap:
    """Capsules bridging the legs, one per height.

    ends : (C, 2, 3) float64 metres, from the left leg's axis to the right's (the person's left is +x).
    radii : (C, 2) float64 metres, each end's radius (a little under its leg's).
    crotch_y : the highest height where the legs are still apart, metres.
    """

    ends: np.ndarray
    radii: np.ndarray
    crotch_y: float


def leg_gap(
    mesh: TriMesh,
    *,
    step_m: float = 0.04,
    slab_m: float = 0.02,
    min_gap_m: float = 0.015,
    half_width_m: float = 0.3,
    fill: float = 0.9,
) -> LegGap | None:
    """Bridge the gap between the legs of `mesh` (metres, Y up, the person's left at +x, standing).

    Every `step_m` up from the ankles, the body's vertices within `slab_m` of that height and within
    `half_width_m` of the mid-plane split into a left and a right leg; while their inner sides are at least
    `min_gap_m` apart, a tapered capsule joins the two legs' centres, each end `fill` times half the leg's
    narrower width. None when no height has two legs (a body not standing apart-legged, or not Y up)."""
    v = mesh.vertices
    y0, height = float(v[:, 1].min()), float(np.ptp(v[:, 1]))
    ends, radii, top = [], [], None
    for y in np.arange(y0 + 2 * step_m, y0 + 0.6 * height, step_m):
        slab = v[(np.abs(v[:, 1] - y) < slab_m) & (np.abs(v[:, 0]) < half_width_m)]
        left, right = slab[slab[:, 0] > 0], slab[slab[:, 0] < 0]
        if len(left) < 8 or len(right) < 8:  # a coarse mesh has no vertices at some heights
            continue
        if left[:, 0].min() - right[:, 0].max() < min_gap_m:
            if ends:
                break
            continue
        centre = [np.r_[leg[:, 0].mean(), y, leg[:, 2].mean()] for leg in (left, right)]
        size = [0.5 * fill * min(np.ptp(leg[:, 0]), np.ptp(leg[:, 2])) for leg in (left, right)]
        ends.append(centre)
        radii.append(size)
        top = float(y)
    if not ends:
        return None
    return LegGap(np.array(ends), np.array(radii), top)
