"""The kimono on the default body: the packaged strokes, and the band where the obi holds the waist.

from kitsuke.dressing.kimono import dress_default_kimono
garment = dress_default_kimono()          # DressedGarment: default_kimono() on default_body()
"""

from __future__ import annotations

from ..errors import InputError
from ..skeleton import INDEX
from .wrap import DressedGarment, WrapParams, wrap

#: Width of a tied obi on the body, metres (a fukuro obi is 31 cm, folded in half lengthwise when tied).
OBI_WIDTH_M = 0.15
#: The obi's lower edge below the rig's spine joint (the natural waist), metres.
OBI_BELOW_WAIST_M = 0.02


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
    the obi band. `body` defaults to `default_body()` (the strokes are drawn on it); `params` defaults to
    WrapParams(hold_band_m=obi_band(body)); a given `params` without a hold band gets the obi band too."""
    import dataclasses

    from ..body import default_body
    from ..pattern import default_kimono
    from . import load_packaged_strokes

    body = default_body() if body is None else body
    p = params or WrapParams()
    if p.hold_band_m is None:
        p = dataclasses.replace(p, hold_band_m=obi_band(body))
    return wrap(body, default_kimono(), load_packaged_strokes("kimono_default"), params=p)
