"""Drags files (SPEC §3.5): a recorded sequence of pins, grabs and moves to replay on a dressed garment.

File layout (`kitsuke.drags` v1)::

    {"format": "kitsuke.drags", "version": 1,
     "steps": [{"pins": [[0.0, 1.2, -0.15]], "grab": [0.0, 1.0, 0.16],
                "path": [[0.0, 1.02, 0.16], [0.0, 1.05, 0.16]]},
               {"unpin": "all"}],
     "meta": {}}                                                   # optional, free-form

Each step, in this order: `unpin` ("all", or points: the pins nearest them go), `pins` (points, each snapped to the
nearest garment vertex), then `grab` (a point on the garment) with its `path` (points, each projected onto the
body surface: the grab's foot goes through them in turn, the garment following), then release. A step may do any
part of this; a `path` needs a `grab`. Points are in metres, world frame (Y up), like the body.

- `read_drags(path)` / `write_drags(drags, path)`: the file, its structure checked (InputError naming it).
- `apply_drags(session, drags)`: replay on a `DragSession`; all or nothing (a step that fails leaves the garment
  as it was before the first step, and the error names the file and the step).
"""

from __future__ import annotations

import json
import os
import re
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np

from .. import limits
from .._files import read_json, write_text_atomic
from ..errors import InputError
from .drag import DragSession, MoveStats, ReleaseStats

FORMAT = "kitsuke.drags"
VERSION = 1
STEP_KEYS = ("unpin", "pins", "grab", "path")


@dataclass(eq=False)
class DragStep:
    """One step of a drags file.

    unpin : "all", (n, 3) float64 metres (unpin the pins nearest these points), or None.
    pins : (n, 3) float64 metres (pin the garment vertices nearest them), or None.
    grab : (3,) float64 metres, the point of the garment to grab, or None.
    path : (m, 3) float64 metres, where the grab goes, in order (each projected onto the body); empty without grab.
    """

    unpin: Literal["all"] | np.ndarray | None = None
    pins: np.ndarray | None = None
    grab: np.ndarray | None = None
    path: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))

    def __post_init__(self) -> None:
        if self.unpin is not None and not (isinstance(self.unpin, str) and self.unpin == "all"):
            self.unpin = _points(self.unpin, "unpin")
        if self.pins is not None:
            self.pins = _points(self.pins, "pins")
        if self.grab is not None:
            g = self.grab
            g = _points([g] if isinstance(g, list | tuple | np.ndarray) and _is_number_list(g) else g, "grab")
            if len(g) != 1:
                raise InputError(f"grab must be one point [x, y, z], got {len(g)}")
            self.grab = g[0]
        self.path = _points(self.path, "path")
        if len(self.path) and self.grab is None:
            raise InputError("a path needs a grab (the point of the garment that moves along it)")


@dataclass(eq=False)
class Drags:
    """A drags file: steps in order; meta (free-form JSON notes); source (the file, named in errors; "" if none)."""

    steps: list[DragStep] = field(default_factory=list)
    meta: dict[str, Any] = field(default_factory=dict)
    source: str = ""

    def __len__(self) -> int:
        return len(self.steps)


def _is_number_list(value: Any) -> bool:
    return all(isinstance(x, int | float | np.number) and not isinstance(x, bool) for x in value)


def _points(value: Any, what: str) -> np.ndarray:
    if isinstance(value, list | tuple) and len(value) == 0:
        return np.zeros((0, 3))
    try:
        arr = np.array(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise InputError(f"{what} must be a list of [x, y, z] points (metres)") from None
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise InputError(f"{what} must be a list of [x, y, z] points (metres), got shape {arr.shape}")
    bad = ~np.isfinite(arr).all(axis=1)
    if bad.any():
        raise InputError(f"{what}: point {int(np.argmax(bad))} holds NaN or infinity")
    limits.check("points", len(arr), f"{what} has {len(arr):,} points")
    return np.ascontiguousarray(arr)


def _step_from_dict(d: Any, k: int) -> DragStep:
    if not isinstance(d, dict):
        raise InputError(f"steps[{k}]: expected an object with {', '.join(STEP_KEYS)}")
    unknown = sorted(set(d) - set(STEP_KEYS))
    if unknown:
        known = ", ".join(STEP_KEYS)
        raise InputError(f"steps[{k}]: unknown field(s) {', '.join(map(repr, unknown))} (known: {known})")
    unpin = d.get("unpin")
    if isinstance(unpin, str) and unpin != "all":
        raise InputError(f'steps[{k}]: unpin must be "all" or a list of points, got {unpin!r}')
    try:
        return DragStep(unpin, d.get("pins"), d.get("grab"), d.get("path", []))
    except InputError as e:
        raise InputError(f"steps[{k}]: {e.message}") from None


def drags_from_dict(d: Any) -> Drags:
    """Drags from the parsed JSON of a drags file; InputError (without a file name) when malformed."""
    if not isinstance(d, dict):
        raise InputError("not a kitsuke drags file (the top level is not an object)")
    if d.get("format") != FORMAT:
        raise InputError(f"not a kitsuke drags file (format is {d.get('format')!r}, expected {FORMAT!r})")
    if d.get("version") != VERSION:
        raise InputError(f"unsupported {FORMAT} version {d.get('version')!r} (this kitsuke reads version {VERSION})")
    steps = d.get("steps")
    if not isinstance(steps, list):
        raise InputError("'steps' must be a list of steps")
    meta = d.get("meta", {})
    if not isinstance(meta, dict):
        raise InputError("'meta' must be an object")
    limits.check("strokes", len(steps), f"the file has {len(steps):,} steps")
    return Drags([_step_from_dict(s, k) for k, s in enumerate(steps)], dict(meta))


def _rows(a: np.ndarray) -> list[list[float]]:
    return [[float(x) for x in row] for row in np.asarray(a).reshape(-1, 3)]


def drags_to_dict(drags: Drags) -> dict[str, Any]:
    """The JSON-ready dict of a drags file."""
    steps = []
    for s in drags.steps:
        d: dict[str, Any] = {}
        if s.unpin is not None:
            d["unpin"] = "all" if isinstance(s.unpin, str) else _rows(s.unpin)
        if s.pins is not None:
            d["pins"] = _rows(s.pins)
        if s.grab is not None:
            d["grab"] = [float(x) for x in s.grab]
            d["path"] = _rows(s.path)
        steps.append(d)
    out: dict[str, Any] = {"format": FORMAT, "version": VERSION, "steps": steps}
    if drags.meta:
        out["meta"] = drags.meta
    return out


_NUMBER_LIST = re.compile(r"\[\s*(-?[0-9][0-9.eE+-]*(?:,\s*-?[0-9][0-9.eE+-]*)*)\s*\]")


def drags_to_json(drags: Drags) -> str:
    """The text of a drags file: indented JSON, each point on one line."""
    text = json.dumps(drags_to_dict(drags), indent=1, allow_nan=False, ensure_ascii=False)
    return _NUMBER_LIST.sub(lambda m: "[" + ", ".join(x.strip() for x in m.group(1).split(",")) + "]", text) + "\n"


def read_drags(path: str | os.PathLike[str]) -> Drags:
    """Read a kitsuke drags file, its structure checked; InputError naming the file."""
    d = read_json(path, what="drags file")
    try:
        drags = drags_from_dict(d)
    except InputError as e:
        raise InputError(e.message, path) from None
    drags.source = str(path)
    return drags


def write_drags(drags: Drags, path: str | os.PathLike[str]) -> None:
    """Write `drags` as a kitsuke drags v1 file, atomically."""
    write_text_atomic(path, drags_to_json(drags))


@dataclass
class StepResult:
    """What one step did: pinned / unpinned vertex indices, the grabbed vertex (-1 if none), each path point's
    move (MoveStats) and the release (ReleaseStats; None without a grab)."""

    pinned: list[int] = field(default_factory=list)
    unpinned: list[int] = field(default_factory=list)
    grabbed: int = -1
    moves: list[MoveStats] = field(default_factory=list)
    release: ReleaseStats | None = None

    def to_dict(self) -> dict[str, Any]:
        ups = [t for m in self.moves for t in m.update_seconds]
        return {
            "pinned": self.pinned,
            "unpinned": self.unpinned,
            "grabbed_vertex": self.grabbed,
            "path_points": len(self.moves),
            "updates": sum(m.updates for m in self.moves),
            "grab_moved_m": round(sum(m.grab_moved_m for m in self.moves), 5),
            "max_vertex_move_m": round(max((m.max_vertex_move_m for m in self.moves), default=0.0), 5),
            "update_ms_median": round(1e3 * float(np.median(ups)), 3) if ups else None,
            "update_ms_max": round(1e3 * max(ups), 3) if ups else None,
            "release": self.release.to_dict() if self.release else None,
        }


def apply_drags(session: DragSession, drags: Drags) -> list[StepResult]:
    """Replay `drags` on `session`, step by step (see the module docstring). All or nothing: on bad input (a pin
    or grab off the garment, a path point off the body, every vertex pinned, ...) the session is restored to
    where it was and InputError names the drags file and the step."""
    if not isinstance(session, DragSession):
        raise InputError("apply_drags needs a DragSession")
    if not isinstance(drags, Drags):
        raise InputError("apply_drags needs Drags (read_drags)")
    if session.grabbed is not None:
        raise InputError("the garment is grabbed: release it before replaying drags", drags.source or None)
    snap = session.snapshot()
    results = []
    k = 0
    try:
        for k, step in enumerate(drags.steps):  # noqa: B007 (k names the failing step below)
            r = StepResult()
            if step.unpin is not None and len(step.unpin):
                unpinned = session.unpin(all=True) if isinstance(step.unpin, str) else session.unpin(step.unpin)
                r.unpinned = [int(i) for i in unpinned]
            if step.pins is not None and len(step.pins):
                r.pinned = [int(i) for i in session.pin(step.pins)]
            if step.grab is not None:
                r.grabbed = session.grab(step.grab).vertex
                for q in step.path:
                    r.moves.append(session.move_to(q))
                r.release = session.release()
            results.append(r)
    except InputError as e:
        session.restore(snap)
        raise InputError(f"step {k}: {e.message}", drags.source or None) from None
    return results
