"""Units and axes of a body mesh: detect them and convert to kitsuke's frame (metres, Y up, facing +Z).

Detection (SPEC §2) works on a standing person:
- up axis: the longest bounding-box side; its sign from the ends (two feet apart at the bottom, one head on top);
- units: from the height in file units (a person is 0.4-2.6 m tall), see `UNIT_RANGES`;
- facing: the feet point forward; in the lowest 6 % of the body, toes reach further from the shins than heels do.
Each guess can be overridden, and the applied conversion is reported.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Literal

import numpy as np

from ..errors import InputError

#: metres per file unit
UNIT_SCALE: dict[str, float] = {"m": 1.0, "dm": 0.1, "cm": 0.01, "mm": 0.001, "in": 0.0254}

#: (unit, lowest height, highest height) in file units, tried in order. A body 30-100 units tall is taken to be in
#: inches (0.76-2.54 m) rather than a 0.3-1 m child in centimetres: pass units="cm" for a small child.
UNIT_RANGES: tuple[tuple[str, float, float], ...] = (
    ("m", 0.0, 3.0),
    ("dm", 3.0, 30.0),
    ("in", 30.0, 100.0),
    ("cm", 100.0, 300.0),
    ("mm", 300.0, 3000.0),
)

Units = Literal["auto", "m", "dm", "cm", "mm", "in"]
Axis = Literal["auto", "+x", "-x", "+y", "-y", "+z", "-z"]

_AXES = {"+x": (0, 1.0), "-x": (0, -1.0), "+y": (1, 1.0), "-y": (1, -1.0), "+z": (2, 1.0), "-z": (2, -1.0)}


@dataclass
class Conversion:
    """What was done to bring a mesh into kitsuke's frame: p_out = scale * rotation @ p_in.

    units : the unit the file was in. up, facing : the file's axes that became +Y and +Z.
    rotation : (3, 3) float64 proper rotation. notes : human-readable lines on what was detected.
    """

    units: str = "m"
    scale: float = 1.0
    up: str = "+y"
    facing: str = "+z"
    rotation: np.ndarray = field(default_factory=lambda: np.eye(3))
    notes: list[str] = field(default_factory=list)

    @property
    def is_identity(self) -> bool:
        return self.scale == 1.0 and np.array_equal(self.rotation, np.eye(3))

    def apply(self, points: np.ndarray) -> np.ndarray:
        """(n, 3) file coordinates -> (n, 3) kitsuke coordinates (metres, Y up, facing +Z)."""
        if self.is_identity:
            return np.array(points, dtype=np.float64)
        return (np.asarray(points, dtype=np.float64) @ self.rotation.T) * self.scale

    def to_dict(self) -> dict:
        d = asdict(self)
        d["rotation"] = self.rotation.tolist()
        return d


def _axis_vector(name: str) -> np.ndarray:
    i, s = _AXES[name]
    v = np.zeros(3)
    v[i] = s
    return v


def detect_up(vertices: np.ndarray) -> tuple[str, str]:
    """Guess the up axis ("+y", "-z", ...) and say why.

    The axis is the longest bounding-box side. Its sign: the lowest 5 % of a standing person holds two feet apart
    (wide spread across the axis), the highest 5 % one head (narrow); measured 2-4x apart on real bodies.
    """
    lo, hi = vertices.min(axis=0), vertices.max(axis=0)
    ext = hi - lo
    i = int(np.argmax(ext))
    h = vertices[:, i]
    across = np.delete(vertices, i, axis=1)

    def spread(mask: np.ndarray) -> float:
        pts = across[mask]
        return float(np.sqrt(((pts - pts.mean(axis=0)) ** 2).sum(axis=1).mean())) if len(pts) else 0.0

    low_end = spread(h < lo[i] + 0.05 * ext[i])
    high_end = spread(h > hi[i] - 0.05 * ext[i])
    sign = "+" if low_end >= high_end else "-"
    name = sign + "xyz"[i]
    feet, head = (low_end, high_end) if sign == "+" else (high_end, low_end)
    return (
        name,
        f"up axis {name}: longest side; feet end {feet / ext[i]:.1%} wide vs head end {head / ext[i]:.1%}",
    )


def detect_units(height: float) -> str:
    for unit, low, high in UNIT_RANGES:
        if low < height <= high:
            return unit
    raise ValueError(f"height {height:g} fits no unit (expected a person 0.4-2.6 m tall in m, dm, in, cm or mm)")


def _rotation_to(up: np.ndarray, facing: np.ndarray) -> np.ndarray:
    """Proper rotation taking `up` to +Y and `facing` to +Z (both unit, orthogonal)."""
    x = np.cross(up, facing)  # becomes +X (the person's left when facing +Z with Y up)
    return np.stack([x, up, facing])  # rows: new axes expressed in old coordinates


def detect_facing(vertices: np.ndarray, up_vec: np.ndarray) -> tuple[str | None, str]:
    """Guess the forward axis from the feet (toes forward of the shins), perpendicular to `up_vec`."""
    h = vertices @ up_vec
    lo, hi = h.min(), h.max()
    height = hi - lo
    feet = vertices[h < lo + 0.06 * height]
    shins = vertices[(h > lo + 0.12 * height) & (h < lo + 0.22 * height)]
    if len(feet) < 3 or len(shins) < 3:
        return None, "facing not detected (too few vertices near the floor)"
    best, best_gap = None, 0.0
    for name in ("+x", "+y", "+z"):
        a = _axis_vector(name)
        if abs(a @ up_vec) > 0.5:
            continue
        centre = float(np.median(shins @ a))
        fwd = float((feet @ a).max() - centre)
        back = float(centre - (feet @ a).min())
        gap = fwd - back  # > 0: toes stick out along +a
        if abs(gap) > abs(best_gap):
            best, best_gap = name, gap
    if best is None or abs(best_gap) < 0.02 * height:
        return None, "facing not detected (feet look symmetric); kept as it is"
    name = best if best_gap > 0 else "-" + best[1]
    return name, f"facing {name}: toes reach {abs(best_gap) / height:.1%} of the height further than heels"


def plan_conversion(
    vertices: np.ndarray,
    *,
    units: Units = "auto",
    up: Axis = "auto",
    facing: Axis = "auto",
    source: str | None = None,
) -> Conversion:
    """Decide the conversion of a body mesh to metres, Y up, facing +Z.

    vertices : (V, 3) float64 in file units. Raises InputError (naming `source`) when the size fits no unit.
    """
    conv = Conversion()
    if up == "auto":
        up, note = detect_up(vertices)
        conv.notes.append(note)
    elif up not in _AXES:
        raise InputError(f"up axis must be one of {', '.join(_AXES)}, got {up!r}", source)
    up_vec = _axis_vector(up)
    if facing == "auto":
        found, note = detect_facing(vertices, up_vec)
        conv.notes.append(note)
        if found is None:  # keep the conventional partner of the up axis (Y up -> +Z, Z up -> -Y, as Blender)
            found = {"+y": "+z", "-y": "-z", "+z": "-y", "-z": "+y", "+x": "+z", "-x": "+z"}[up]
        facing = found  # type: ignore[assignment]
    elif facing not in _AXES:
        raise InputError(f"facing must be one of {', '.join(_AXES)}, got {facing!r}", source)
    face_vec = _axis_vector(facing)
    if abs(face_vec @ up_vec) > 0.5:
        raise InputError(f"facing {facing} cannot be along the up axis {up}", source)
    conv.up, conv.facing = up, facing
    conv.rotation = _rotation_to(up_vec, face_vec)
    height = float(np.ptp(vertices @ up_vec))
    if units == "auto":
        try:
            units = detect_units(height)  # type: ignore[assignment]
        except ValueError as e:
            raise InputError(str(e), source) from None
        conv.notes.append(f"units {units}: height {height:g} file units = {height * UNIT_SCALE[units]:.3f} m")
    elif units not in UNIT_SCALE:
        raise InputError(f"units must be one of {', '.join(UNIT_SCALE)}, got {units!r}", source)
    conv.units, conv.scale = units, UNIT_SCALE[units]
    return conv
