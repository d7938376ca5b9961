"""Bottoms raised to where they fit: a skirt, trousers or a waistband goes up the body until its loops are no
shorter than the body round them.

A placement is a layout, and GarmentCode lays its bottoms at the hips whatever their waist: a pencil skirt cut for
the waist, dressed from strokes carried off that layout, rests 10 cm below its waist round the widest part of the
hips and must stretch 38 % to go round them (measured on a sampled design: within every target once raised 10
cm). A person pulls such a garment up until it sits; this does the same to a garment resting on the body: it
cuts the cloth into horizontal loops (`kitsuke.metrics.worn_loop`) and finds the smallest lift after which no
loop is more than `tolerance` shorter than the body's girth inside it at its new height, its top going no higher
than the waist (`rise_limit`: a skirt too small round the hips is out of target, not worn round the ribs). A
garment that rests on the shoulders (a top, a dress) hangs from them and is never lifted; one that slid down from
them in the settle (a shirt over a skirt that pulled it 7-15 cm down) is.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..geometry import TriMesh
from ..geometry.surface import Surface
from ..metrics import WornLoop, body_section, tape_inside, worn_loop


@dataclass(frozen=True)
class FitSettings:
    """How a garment resting on the body is raised to fit (`fitting_lift`).

    tolerance : a loop of cloth may be this share shorter than the body round it (it stretches that much).
    step_m : the loops are cut, and the lifts tried, this far apart, metres.
    max_lift_m : the most a garment is raised, metres.
    margin_m : a loop moved up takes in the body this much beyond its own path (the body leans), metres.
    min_gain : a lift that cannot make every loop fit is made only when it makes the worst one fit by at least
        this share more.
    shoulder_normal, rest_m, rest_share : a garment with at least `rest_share` of its vertices within `rest_m`
        metres of skin whose outward normal points up by more than `shoulder_normal` (the shoulders' tops)
        hangs from the shoulders and is not raised (GarmentCode's shirt on mean_all: 6.5 % of its vertices; shirts
        over skirts that slid 7-15 cm down: 0-0.1 %, and two that tore at the sleeve once raised: 1.6-2.8 %).
        Only skin in the upper `shoulder_height` share of the body counts (a long skirt lies on the feet's tops).
    """

    tolerance: float = 0.03
    step_m: float = 0.01
    max_lift_m: float = 0.25
    margin_m: float = 0.03
    min_gain: float = 0.02
    shoulder_normal: float = 0.6
    rest_m: float = 0.015
    rest_share: float = 0.01
    shoulder_height: float = 0.5

    def __post_init__(self) -> None:
        if not (
            0 <= self.tolerance < 1
            and self.step_m > 0
            and self.max_lift_m >= 0
            and self.margin_m >= 0
            and self.min_gain >= 0
            and -1 <= self.shoulder_normal <= 1
            and self.rest_m > 0
            and 0 <= self.rest_share <= 1
            and 0 <= self.shoulder_height <= 1
        ):
            raise InputError(
                "FitSettings: tolerance in [0, 1), step_m > 0, the others >= 0 (shoulder_normal in [-1, 1])"
            )


def hangs_from_shoulders(positions: np.ndarray, surface: Surface, settings: FitSettings) -> bool:
    """Does the cloth (V, 3) metres rest on skin facing up (`FitSettings.shoulder_normal`) in the upper part of the
    body (`shoulder_height`)?"""
    face, point, distance = surface.nearest(positions)
    low, high = surface.vertices[:, 1].min(), surface.vertices[:, 1].max()
    near = (distance <= settings.rest_m) & (point[:, 1] >= high - settings.shoulder_height * (high - low))
    up = surface.normals_at(face[near])[:, 1] > settings.shoulder_normal
    return bool(up.sum() >= settings.rest_share * len(positions))


class _Sections:
    """The body's cross-sections (`body_section`) by height, each cut once (heights on one grid repeat)."""

    def __init__(self, surface: Surface):
        self.surface, self.cut = surface, {}
        heights = surface.vertices[surface.faces, 1]
        self.low, self.high = heights.min(axis=1), heights.max(axis=1)

    def at(self, y: float) -> np.ndarray:
        key = round(y, 6)
        if key not in self.cut:
            near = (self.low <= key) & (self.high >= key)  # only the faces at that height are cut
            self.cut[key] = body_section(TriMesh(self.surface.vertices, self.surface.faces[near]), key)
        return self.cut[key]


def body_loops(
    positions: np.ndarray, faces: np.ndarray, rest_corners: np.ndarray, sections: _Sections, step_m: float
) -> list[tuple[WornLoop, float]]:
    """The closed horizontal loops of the cloth that go round the body, one every `step_m` metres of height (the
    front-most at each), with the body's girth inside each (metres). A loop round no body (a fold closed on
    itself) is left out."""
    lo, hi = float(positions[:, 1].min()), float(positions[:, 1].max())
    out = []
    for y in np.arange(lo + 0.5 * step_m, hi, step_m):
        loop = worn_loop(positions, faces, rest_corners, float(y))
        if loop is not None and (tape := tape_inside(sections.at(float(y)), loop.ring)) > 0.0:
            out.append((loop, tape))
    return out


def shortfall(loops: list[tuple[WornLoop, float]], sections: _Sections, lift_m: float, margin_m: float) -> float:
    """The largest share by which a loop (`body_loops`), raised `lift_m` metres, is shorter than the body's girth
    inside it there (negative: every loop longer); -inf without loops."""
    worst = -np.inf
    for loop, here in loops:
        tape = here if not lift_m else tape_inside(sections.at(loop.height_m + lift_m), loop.ring, margin_m=margin_m)
        if tape > 0.0:
            worst = max(worst, 1.0 - loop.rest_m / tape)
    return float(worst)


def rise_limit(loops: list[tuple[WornLoop, float]], sections: _Sections, settings: FitSettings) -> float:
    """How far up (metres) the garment's top loop (`body_loops`) may go: where the body inside it is narrowest
    within `max_lift_m` above it (the waist, for a garment whose top is below it), and on up to the last height,
    in `step_m` steps, at which it is at most `tolerance` wider than there. A bottom is worn from its waist down: a
    tiered skirt too small round the hips fits round the ribs too, 23 cm higher, and is a skirt no more.
    `max_lift_m` where the body is narrowest at the top loop itself (a strapless top under the bust) or does not
    widen again."""
    top = max((loop for loop, _ in loops), key=lambda loop: loop.height_m, default=None)
    if top is None:
        return settings.max_lift_m
    steps = int(round(settings.max_lift_m / settings.step_m))
    girth = np.array(
        [
            tape_inside(sections.at(top.height_m + k * settings.step_m), top.ring, margin_m=settings.margin_m)
            for k in range(steps + 1)
        ]
    )
    girth[girth <= 0.0] = np.inf  # no body inside: no waist there
    waist = int(np.argmin(girth))
    if waist == 0 or not np.isfinite(girth[waist]):
        return settings.max_lift_m
    above = girth[waist:]
    wider = np.flatnonzero(np.isfinite(above) & (above > girth[waist] * (1.0 + settings.tolerance)))
    return (waist + int(wider[0]) - 1) * settings.step_m if len(wider) else settings.max_lift_m


def fitting_lift(
    positions: np.ndarray,
    faces: np.ndarray,
    rest_corners: np.ndarray,
    surface: Surface,
    settings: FitSettings | None = None,
) -> float:
    """How far up (metres, >= 0) the garment resting on the body at `positions` (V, 3) metres (faces (F, 3),
    rest_corners (F, 3, 2) metres: `ClothModel.rest_corners`; the body's `surface`) must go for its loops to fit
    the body (module docstring): the smallest lift, in `step_m` steps up to `max_lift_m`, after which no loop is
    more than `tolerance` too short; where none is, the one that leaves the worst loop least short, if that gains
    `min_gain`; never past `rise_limit`; 0 for a garment that fits, or hangs from the shoulders."""
    s = settings or FitSettings()
    sections = _Sections(surface)
    loops = body_loops(positions, faces, rest_corners, sections, s.step_m)
    here = shortfall(loops, sections, 0.0, s.margin_m)
    if here <= s.tolerance or hangs_from_shoulders(positions, surface, s):
        return 0.0
    best_lift, best = 0.0, here
    highest = rise_limit(loops, sections, s)
    for lift in np.arange(1, int(round(s.max_lift_m / s.step_m)) + 1) * s.step_m:
        if lift > highest + 1e-9:
            break
        worst = shortfall(loops, sections, float(lift), s.margin_m)
        if worst <= s.tolerance:
            return float(lift)
        if worst < best:
            best_lift, best = float(lift), worst
    return best_lift if best <= here - s.min_gain else 0.0
