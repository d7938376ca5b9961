"""Sewing: stretched cloth pulled back to its rest lengths a little at a time by the dynamic solver, weightless.

A garment whose seams start far apart (pieces laid flat round the body, or grown round it from strokes) has the
triangles across each open seam stretched to many times their length. A relaxation that closes them in a few large
steps moves cloth tens of centimetres at once, through an arm or a leg, and the collision then pushes it out on
the limb's far side (torn round the limb). Sewing closes the same seams the way a garment simulator does: the
dynamic solver (`step`, XPBD with the body's collision at every step) runs without gravity while each stretched
edge's rest length shrinks by at most `shrink_m` a frame from its length at the start down to the pattern's. Cloth
then moves at most a few centimetres a frame and goes round a limb, not through it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ComputationError, InputError
from ._collide import BodyCollider
from ._dynamics import DynamicsParams, MovingBody, dynamics_data, step
from ._model import ClothModel, ClothState


@dataclass(frozen=True)
class SewStats:
    """What `sew` did: frames simulated, the largest excess over rest length (metres) at the start, and whether
    the solver diverged (the cloth was then put back where it started)."""

    frames: int
    excess_m: float
    diverged: bool = False


def sew(
    model: ClothModel,
    state: ClothState,
    collider: BodyCollider,
    *,
    shrink_m: float = 0.01,
    max_frames: int = 90,
    settle_frames: int = 15,
    damping: float = 10.0,
    min_excess_m: float = 0.01,
    fps: float = 30.0,
) -> SewStats:
    """Pull every edge longer than its rest length back to it, `shrink_m` metres a frame at most, in the dynamic
    solver without gravity (in place; `state.pinned` held; velocities cleared at the end).

    shrink_m : how much an edge's rest length shrinks per frame, metres (it starts at the edge's length).
    max_frames : most frames; an edge still longer then is left to the caller's relaxation.
    settle_frames : frames after every rest length has reached the pattern's, for the cloth to come to rest.
    damping : fraction of the velocity lost per second: high, the cloth is pulled, not flung.
    min_excess_m : nothing is done when no edge is that much longer than its rest length (a closed garment).
    fps : frames per simulated second.
    Returns SewStats. A step that diverges puts the cloth back where it started (`diverged`).
    """
    if not (shrink_m > 0 and max_frames >= 0 and settle_frames >= 0 and fps > 0):
        raise InputError("sew: shrink_m and fps must be > 0, max_frames and settle_frames >= 0")
    params = DynamicsParams(gravity=0.0, damping=damping)
    data = dynamics_data(model, params)
    pattern = data.stretch_rest.copy()
    x = state.positions
    pairs = data.stretch_pairs
    now = np.linalg.norm(x[pairs[:, 1]] - x[pairs[:, 0]], axis=1)
    excess = float((now - pattern).max(initial=0.0))
    if excess < min_excess_m or not max_frames:
        return SewStats(0, excess)
    # Start each edge where it is (no snap), within the strain limit of its own rest length.
    rest = np.maximum(pattern, now / (1.0 + params.max_strain))
    before = x.copy()
    body = MovingBody.of(collider)
    frames = after = 0
    try:
        while frames < max_frames and after < settle_frames:
            rest = np.maximum(pattern, rest - shrink_m)
            data.stretch_rest[:] = rest
            step(model, state, body, 1.0 / fps, params, data)
            # Quasi-static: a frame's pull is not carried into the next as speed (a tube laid as two panels round a
            # sphere, kept moving, was flung 15 cm up off it within ten frames).
            state.velocities[:] = 0.0
            frames += 1
            if (rest <= pattern).all():
                after += 1
    except ComputationError:
        state.positions[:] = before
        state.velocities = None
        return SewStats(frames, excess, diverged=True)
    state.velocities = None
    return SewStats(frames, excess)
