"""Resource limits on inputs, checked before the work (SPEC §2): a file that would take hours or all the memory is
refused in one line that names the limit and how to raise it.

The defaults are far above any real garment, body or clip. Raise one for a run with

    kitsuke --limit triangles=5e6 pattern mesh big.json -o big.obj      # any command, repeatable
    KITSUKE_LIMIT_TRIANGLES=5e6 kitsuke pattern mesh big.json -o big.obj

or from Python with `with kitsuke.limits.raised(triangles=5e6): ...`.
"""

from __future__ import annotations

import contextlib
import dataclasses
import math
import os
from collections.abc import Iterator
from contextvars import ContextVar
from dataclasses import dataclass

from .errors import InputError


@dataclass(frozen=True)
class Limits:
    """The largest input kitsuke works on.

    Attributes
    ----------
    file_mb : size of any input file, MB.
    edge_m : length of a pattern piece's edge (curves included), metres. Generous: random GarmentCode designs
        include circle skirts with a 12.6 m hem (seed 6626); what it stops is the 10⁷ m arc that took hours.
    piece_m2 : area of one pattern piece, square metres.
    pieces, seams : pieces and seams in one pattern.
    triangles : triangles in a mesh read or made (a body, a meshed pattern).
    vertices : vertices in a mesh read.
    strokes : stroke pairs in a strokes file; points : points in one stroke or one drag path.
    frames : frames in a pose sequence, BVH or video.
    image_mpx : pixels of one image or video frame, millions.
    """

    file_mb: float = 1024.0
    edge_m: float = 50.0
    piece_m2: float = 100.0
    pieces: int = 1000
    seams: int = 10_000
    triangles: int = 2_000_000
    vertices: int = 2_000_000
    strokes: int = 1000
    points: int = 100_000
    frames: int = 1_000_000
    image_mpx: float = 100.0

    def raised(self, **changes: float) -> Limits:
        """A copy with some limits changed; ValueError for an unknown name or a value that is not positive."""
        fields = {f.name: f for f in dataclasses.fields(self)}
        out = {}
        for name, value in changes.items():
            if name not in fields:
                raise ValueError(f"unknown limit {name!r} (known: {', '.join(fields)})")
            value = float(value)
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f"limit {name} must be a positive number, got {value:g}")
            out[name] = int(value) if fields[name].type in (int, "int") else value
        return dataclasses.replace(self, **out)


#: The unit each limit is counted in, for messages.
UNITS = {"file_mb": " MB", "edge_m": " m", "piece_m2": " m²", "image_mpx": " megapixels"}


def parse_limit(text: str) -> tuple[str, float]:
    """'NAME=VALUE' -> (name, value); InputError naming the problem (used by the CLI and the environment)."""
    name, sep, value = text.partition("=")
    name = name.strip().lower()
    try:
        Limits().raised(**{name: float(value)})
    except ValueError as e:
        raise InputError(str(e) if sep else f"expected NAME=VALUE, got {text!r}", "--limit") from None
    return name, float(value)


def _from_environment() -> Limits:
    changes = {}
    for f in dataclasses.fields(Limits):
        value = os.environ.get(f"KITSUKE_LIMIT_{f.name.upper()}")
        if value is not None:
            try:
                changes[f.name] = parse_limit(f"{f.name}={value}")[1]
            except InputError as e:
                raise InputError(e.message, f"KITSUKE_LIMIT_{f.name.upper()}") from None
    return Limits().raised(**changes)


_current: ContextVar[Limits | None] = ContextVar("kitsuke_limits", default=None)


def current() -> Limits:
    """The limits in force: the defaults, changed by KITSUKE_LIMIT_<NAME> variables and `raised`."""
    limits = _current.get()
    return _from_environment() if limits is None else limits


@contextlib.contextmanager
def raised(**changes: float) -> Iterator[Limits]:
    """Run a block with some limits changed (e.g. `raised(triangles=5e6)`)."""
    token = _current.set(current().raised(**changes))
    try:
        yield _current.get()
    finally:
        _current.reset(token)


def check(name: str, value: float, what: str, path: str | os.PathLike[str] | None = None) -> None:
    """Raise InputError when `value` exceeds the current limit `name`.

    what : the sentence's subject, e.g. "the pattern would mesh to 3,200,000 triangles".
    """
    limit = getattr(current(), name)
    if value > limit:  # also False for NaN: callers check finiteness themselves
        shown = (f"{limit:,}" if isinstance(limit, int) else f"{limit:,g}") + UNITS.get(name, "")
        raise InputError(
            f"{what}, over the limit of {shown} (raise it with --limit {name}=N or KITSUKE_LIMIT_{name.upper()}=N)",
            path,
        )


def check_image(width: int, height: int, path: str | os.PathLike[str] | None = None) -> None:
    """`check` of an image's or video frame's size against `image_mpx`."""
    check("image_mpx", width * height / 1e6, f"the image is {width:,}×{height:,} pixels", path)
