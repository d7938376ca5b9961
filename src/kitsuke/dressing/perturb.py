"""Strokes changed as a hand would draw them differently: for robustness tests and benchmarks.

    from kitsuke.dressing import HandPerturbation, perturb_strokes
    shaky = perturb_strokes(strokes, surface, np.random.default_rng(7))

Each body stroke (drawn points; laser strokes are left alone) is made longer or shorter about its middle, moved
along the surface, and sometimes drawn the other way; one stroke of several may be left out. The pattern strokes
stay as they are, so the pairs no longer agree in length, place or direction, as a novice's would not.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..geometry.surface import Surface
from ._polyline import arc_length, interpolate_polyline
from .strokes import BodyStroke, StrokePair, Strokes


@dataclass(frozen=True)
class HandPerturbation:
    """How far `perturb_strokes` may change a stroke set.

    length : (low, high) factor on each body stroke's length, drawn uniformly.
    shift_m : each body stroke moves along the surface by up to this, metres, in a random direction.
    backwards : chance that a body stroke is drawn the other way.
    drop_one : leave out one stroke (chosen at random) when there are at least two.
    """

    length: tuple[float, float] = (0.7, 1.3)
    shift_m: float = 0.02
    backwards: float = 0.5
    drop_one: bool = True

    def __post_init__(self) -> None:
        lo, hi = self.length
        if not (0 < lo <= hi and self.shift_m >= 0 and 0 <= self.backwards <= 1):
            raise InputError("HandPerturbation: 0 < length low <= high, shift_m >= 0, 0 <= backwards <= 1 required")


def scale_polyline(points: np.ndarray, factor: float) -> np.ndarray:
    """A polyline (n, 3) made `factor` times as long about its middle, with as many points: cut short, or
    continued straight along its end directions."""
    s = arc_length(points)
    total = float(s[-1])
    want = np.linspace(0.5 * total * (1 - factor), 0.5 * total * (1 + factor), len(points))
    out = interpolate_polyline(points, want)
    head = points[1] - points[0]
    tail = points[-1] - points[-2]
    head /= max(float(np.linalg.norm(head)), 1e-300)
    tail /= max(float(np.linalg.norm(tail)), 1e-300)
    before, after = want < 0, want > total
    out[before] = points[0] + want[before, None] * head
    out[after] = points[-1] + (want[after, None] - total) * tail
    return out


def perturb_strokes(
    strokes: Strokes,
    surface: Surface,
    rng: np.random.Generator,
    hand: HandPerturbation | None = None,
) -> Strokes:
    """`strokes` (target "body", drawn body strokes) as another hand would draw them (see HandPerturbation);
    the body points are projected back onto `surface`. Pairs keep their ids and order; `meta["perturbed"]`
    records what changed per stroke."""
    h = hand or HandPerturbation()
    pairs = list(strokes.pairs)
    dropped = None
    if h.drop_one and len(pairs) >= 2:
        dropped = int(rng.integers(len(pairs)))
        pairs.pop(dropped)
    out, notes = [], []
    for p in pairs:
        if p.body.is_laser:
            out.append(p)
            continue
        pts = np.asarray(p.body.points, dtype=np.float64)
        factor = float(rng.uniform(*h.length))
        pts = scale_polyline(pts, factor)
        on = surface.closest(pts)
        normals = surface.normals_at(on.faces)
        d = rng.normal(size=3)
        d = d - normals.mean(axis=0) * float(d @ normals.mean(axis=0))
        d /= max(float(np.linalg.norm(d)), 1e-300)
        shift = float(rng.uniform(0.0, h.shift_m))
        pts = surface.closest(on.points + shift * d).points
        back = bool(rng.random() < h.backwards)
        if back:
            pts = pts[::-1]
        out.append(StrokePair(p.id, p.pattern, BodyStroke(points=np.ascontiguousarray(pts))))
        notes.append({"id": p.id, "length": round(factor, 3), "shift_m": round(shift, 4), "backwards": back})
    meta = dict(strokes.meta)
    meta["perturbed"] = {"dropped": None if dropped is None else strokes.pairs[dropped].id, "strokes": notes}
    return dataclasses.replace(strokes, pairs=out, meta=meta)
