"""The kimono on the default body: the packaged strokes, the band where the obi holds the waist, and sleeves
that hang.

from kitsuke.dressing.kimono import dress_default_kimono, kimono_params
garment = dress_default_kimono()          # DressedGarment: default_kimono() on default_body()
params = kimono_params(body)              # WrapParams for any kimono pattern on a rigged body
"""

from __future__ import annotations

import dataclasses

import numpy as np

from ..cloth import ClothParams
from ..errors import InputError
from ..skeleton import INDEX
from .strokes import Strokes
from .wrap import DressedGarment, WrapParams, wrap
from .wrap_settings import DrapeSettings

#: Width of a tied obi on the body, metres (a fukuro obi is 31 cm, folded in half lengthwise when tied).
OBI_WIDTH_M = 0.15
#: The obi's lower edge below the rig's spine joint (the natural waist), metres.
OBI_BELOW_WAIST_M = 0.02
#: The growth's hang (`GrowSettings.hang`) for a kimono: its sleeves' lower halves hang as bags below the arms.
KIMONO_HANG = 2.0
#: How far a kimono lies off the skin, metres: it is worn over a hadajuban and a nagajuban (under-kimono), each of
#: about a millimetre, so its contact offset is 3 mm where a garment worn on the skin has ClothParams' 1 mm. (Also
#: measured: at 1 mm the polish pressed the crossed fronts into each other, 157 triangles folded.)
KIMONO_OFFSET_M = 0.003


def is_kimono(pattern) -> bool:
    """Whether `pattern` (a kitsuke Pattern) is a kimono made by `kitsuke.pattern.make_kimono` (its meta says so,
    also after a round trip through the kitsuke pattern JSON)."""
    return "kimono" in getattr(pattern, "meta", {})


def check_kimono(pattern) -> None:  # noqa: ANN001 - a Pattern
    """InputError naming the pattern's file unless it is a kimono (`is_kimono`)."""
    if not is_kimono(pattern):
        raise InputError("this pattern is not a kimono (made by `kitsuke pattern kimono`: no obi line)", pattern.source)


def kimono_params(body, params: WrapParams | None = None, *, hang: float | None = None) -> WrapParams:
    """`params` (default WrapParams()) made right for a kimono: sleeves that hang, the cloth KIMONO_OFFSET_M off
    the body (where `params` keeps ClothParams' default offset), on a rigged body the waist held in the obi
    band (where `params` holds no band), and no drape (where `params` keeps the default one). `hang` sets the
    growth's hang; None keeps a hang that `params` sets and gives KIMONO_HANG where it sets none (0)."""
    p = params or WrapParams()
    changes: dict = {}
    if p.cloth.contact_offset_m == ClothParams().contact_offset_m:
        changes["cloth"] = dataclasses.replace(p.cloth, contact_offset_m=KIMONO_OFFSET_M)
    if hang is not None or p.grow.hang == 0.0:
        changes["grow.hang"] = KIMONO_HANG if hang is None else hang
    if p.settle.hold_band_m is None and getattr(body, "rig", None) is not None:
        changes["settle.hold_band_m"] = obi_band(body)
    if p.drape == DrapeSettings():
        # Its sleeves hang by the growth's hang and it is held in the obi band: on the demo kimono the drape
        # added 3 s (and 2 s of polish) and left 5.1 % max strain against 4.9 % without it.
        changes["drape.seconds"] = 0.0
    return p.changed(changes)


def obi_band(body) -> tuple[float, float]:
    """(low, high) heights in metres of the obi on `body` (a rigged `kitsuke.body.Body`): from just below the
    natural waist (the rig's spine joint) up by the obi's width. The wrap pins the kimono there for the settle."""
    rig = getattr(body, "rig", None)
    if rig is None:
        raise InputError("the obi band needs a rigged body (its spine joint marks the waist)", body.source or None)
    low = float(rig.joints[INDEX["spine"], 1]) - OBI_BELOW_WAIST_M
    return low, low + OBI_WIDTH_M


def dress_default_kimono(body=None, *, params: WrapParams | None = None) -> DressedGarment:
    """Wrap `default_kimono()` on the default body with the packaged strokes `kimono_default`, its waist held in
    the obi band and its sleeves hanging. `body` defaults to `default_body()` (the strokes are drawn on it);
    `params` go through `kimono_params` (a band and a hang they set are kept)."""
    from ..pattern import default_kimono

    return dress_kimono(default_kimono(), body, params=params)


def dress_kimono(pattern, body=None, *, params: WrapParams | None = None) -> DressedGarment:  # noqa: ANN001
    """Wrap a kimono `pattern` (from `kitsuke.pattern.make_kimono`) on `body` (default `default_body()`), its waist
    held in the obi band and its sleeves hanging, with the packaged strokes `kimono_default` (drawn on the standard
    kimono, carried to other sizes by `carried_strokes`).
    InputError when the pattern is not a kimono."""
    from ..body import default_body
    from ..pattern import default_kimono
    from . import load_packaged_strokes

    check_kimono(pattern)
    body = default_body() if body is None else body
    p = params or WrapParams()
    if p.settle.hold_band_m is None:  # obi_band raises for a body without a rig
        p = p.changed({"settle.hold_band_m": obi_band(body)})
    strokes = carried_strokes(load_packaged_strokes("kimono_default"), default_kimono(), pattern)
    return wrap(body, pattern, strokes, params=kimono_params(body, p))


def carried_strokes(strokes: Strokes, drawn_on, pattern) -> Strokes:  # noqa: ANN001 - Patterns
    """`strokes` drawn on the kimono `drawn_on`, carried to the kimono `pattern` of other sizes: each pattern
    stroke's points scaled from its piece's bounds on the one to the same piece's bounds on the other (the
    generator makes the same pieces at every size); the body strokes stay."""
    old = {pc.name: pc.bounds for pc in drawn_on.pieces}
    new = {pc.name: pc.bounds for pc in pattern.pieces}
    pairs = []
    for pair in strokes.pairs:
        name = pair.pattern.piece
        if name not in old or name not in new:
            raise InputError(f"stroke {pair.id}: the kimono has no piece {name!r}", pattern.source)
        (a0, a1), (b0, b1) = old[name], new[name]
        points = b0 + (pair.pattern.points - a0) * (b1 - b0) / np.maximum(a1 - a0, 1e-9)
        pairs.append(dataclasses.replace(pair, pattern=dataclasses.replace(pair.pattern, points=points)))
    return dataclasses.replace(strokes, pairs=pairs)
