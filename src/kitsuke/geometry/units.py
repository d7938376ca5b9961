"""Units and axes of a body mesh: detect them and convert to kitsuke's frame (metres, Y up, facing +Z).

Detection (SPEC §2) reads the body's anatomy, so it works in any pose (standing, T-pose, A-pose, arms down, sitting):
- up axis: of the six axis directions, the one that runs from two feet to one head (see `up_scores`), not the longest
  side (a T-pose can be wider than tall, a sitting body is not much taller than deep);
- units: from the extent along up in file units (a person is 0.3-3 m tall, standing or sitting), see `UNIT_RANGES`;
  where inches and centimetres both fit, the head's size decides (`detect_units`);
- facing: the feet point forward; in the lowest 6 % of the body, toes stick out further beyond the shins than
  heels do (seated too: a seated person's shins stand on the feet as a standing person's do).
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
#: inches (0.76-2.54 m) unless its head is the size of a head in centimetres (a seated adult or a small child in cm,
#: see `detect_units`); pass units= to be sure.
UNIT_RANGES: tuple[tuple[str, float, float], ...] = (
    ("m", 0.0, 3.0),
    ("dm", 3.0, 30.0),
    ("in", 30.0, 100.0),
    ("cm", 100.0, 300.0),
    ("mm", 300.0, 3000.0),
)

#: A head's size across the up axis (the top 10 % of a body, back of the head to the nose tip), metres: 0.19-0.23
#: on adults (0.21 on the default body), ~0.17 on infants.
HEAD_SIZE_M = 0.2

Units = Literal["auto", "m", "dm", "cm", "mm", "in"]
Axis = Literal["auto", "+x", "-x", "+y", "-y", "+z", "-z"]

_AXES = {"+x": (0, 1.0), "-x": (0, -1.0), "+y": (1, 1.0), "-y": (1, -1.0), "+z": (2, 1.0), "-z": (2, -1.0)}
_DIRECTIONS = tuple(_AXES)  # +x, -x, +y, -y, +z, -z: the order of `up_scores`

# Where the up cues look along a candidate axis, as fractions of the body's extent along it, from one end.
_HEAD_END = 0.10  # a head: the crown down to about the nose
_BELOW_HEAD = (0.15, 0.30)  # below a head: shoulders and upper arms
_LEGS_END = 0.15  # feet, ankles and lower shins (a seated body's too)
_LEGS_SLICES = 6  # slices of 2.5 % in _LEGS_END
_GAP = 0.025  # a gap this wide (fraction of the largest extent, ~4 cm on an adult) separates two legs
_LEGS_WEIGHT = 0.5  # the legs cue (0-1) against the head cue (a log ratio: 0.75-2.1 on the bodies measured)
_MIN_SCORE = 0.3  # below it no head over legs was recognised, and the longest side is taken instead


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


def _extent_across(across: np.ndarray) -> float:
    """Longest side of the bounding box of points given as (2, n) coordinates across an axis, file units; 0 for
    no points. Rows, not columns: a reduction along contiguous rows is ~100x faster than down (n, 2) columns."""
    return float((across.max(axis=1) - across.min(axis=1)).max()) if across.shape[1] else 0.0


def _head_likeness(across: np.ndarray, depth: np.ndarray, length: float) -> tuple[float, float]:
    """How much one end of the body looks like the top of a head: (cue >= 0, the end's size across in file units).

    across : (2, V) vertex coordinates across the axis. depth : (V,) distance from that end along the axis, as a
    fraction of `length` (the body's extent along the axis, file units).
    A head is a small end that widens below into shoulders: the cue is log(size at 15-30 % / size of the end
    10 %), 0.75 (arms down) to 2.1 (T-pose) on a head, <= 0 at feet, hands and legs, which are as wide as what
    follows them. Two gates (1 on a head, 0 where they fail) keep other small ends out:
    - compact: a head is 0.12-0.16 of the stature across; the back or the buttocks at an end of the front-back
      axis are 0.7-2.5 times that axis' length across;
    - upright: a person is at most ~1.45 times as wide (any way across) as tall along up (a seated T-pose); along
      the front-back axis they are 2-4 times as tall as deep, and there the toes of a foot stepping forward, or
      the hands of arms held forward, would otherwise pass for a head.
    """
    size = _extent_across(across)
    end = _extent_across(across[:, depth <= _HEAD_END])
    below = _extent_across(across[:, (depth >= _BELOW_HEAD[0]) & (depth <= _BELOW_HEAD[1])])
    if end <= 0.0 or below <= 0.0 or length <= 0.0:
        return 0.0, end
    compact = np.clip((0.4 - end / length) / 0.2, 0.0, 1.0)  # 1 up to 0.2 of the length, 0 from 0.4
    upright = np.clip((1.8 - size / length) / 0.3, 0.0, 1.0)  # 1 up to 1.5 lengths across, 0 from 1.8
    return float(compact * upright) * max(0.0, float(np.log(below / end))), end


def _split_fraction(across: np.ndarray, depth: np.ndarray, gap: float) -> float:
    """Fraction (0-1) of the slices near one end that fall apart in two or more pieces, as two legs do.

    across : (2, V) vertex coordinates across the axis. depth : (V,) distance from that end, fraction of the
    extent along the axis. gap : file units. The lowest 15 % is cut in 6 slices; a slice is split when its vertices,
    sorted along either across-axis, leave a gap wider than `gap`. A 1D gap rather than 2D connected components: it
    needs no grid, and a coarse mesh (vertices 2-3 cm apart) does not break a leg's ring into pieces.
    """
    near = depth < _LEGS_END
    split = np.zeros(_LEGS_SLICES, dtype=bool)
    if not near.any():
        return 0.0
    slab = np.minimum((depth[near] * (_LEGS_SLICES / _LEGS_END)).astype(np.int64), _LEGS_SLICES - 1)
    for c in across[:, near]:
        span = float(np.ptp(c))
        if span <= gap:
            continue
        # one sort orders by slice, then by position in the slice: key = slice index + position scaled into [0, 1)
        key = np.sort(slab + (c - c.min()) / (span * (1.0 + 1e-9)))
        same = np.floor(key[1:]) == np.floor(key[:-1])
        wide = same & (np.diff(key) > gap / span)
        split[np.floor(key[1:][wide]).astype(np.int64)] = True
    return float(split.mean())


def _end_cues(vertices: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Head and legs cues at both ends of the three axes.

    vertices : (V, 3) file units. Returns head (3, 2) (`_head_likeness`) and legs (3, 2) (`_split_fraction`),
    indexed [axis, end], end 0 the low end and 1 the high end.
    """
    lo, ext = vertices.min(axis=0), np.ptp(vertices, axis=0)
    gap = _GAP * float(ext.max())
    head, legs = np.zeros((3, 2)), np.zeros((3, 2))
    for k in range(3):
        t = (vertices[:, k] - lo[k]) / ext[k] if ext[k] > 0 else np.zeros(len(vertices))
        across = np.delete(vertices, k, axis=1).T.copy()  # (2, V): see _extent_across
        for end, depth in enumerate((t, 1.0 - t)):
            head[k, end] = _head_likeness(across, depth, float(ext[k]))[0]
            legs[k, end] = _split_fraction(across, depth, gap)
    return head, legs


def up_scores(vertices: np.ndarray) -> np.ndarray:
    """(6,) how well each direction +x, -x, +y, -y, +z, -z runs from a person's feet to their head (higher: better).

    vertices : (V, 3) in file units, axis-aligned (any units: every length is a fraction of the body's own).
    Direction +k scores: head cue at its top end - head cue at its bottom end + 0.5 x (legs cue at the bottom -
    legs cue at the top); -k scores the opposite. Both ends are compared, so a cue that an axis shows at both ends
    (hands at both ends of the left-right axis) cancels. Neither cue depends on the arms or on sitting:
    - head (`_head_likeness`): the top 10 % is one small end, far narrower than the shoulders below it;
    - legs (`_split_fraction`): the lowest 15 % is two feet and shins, split by a gap in most slices, while the top
      15 % is head and neck in one piece. Legs together still leave a gap at the ankles; where they do not, the
      head cue alone decides.
    The longest side is no cue: a T-pose can be wider than tall, a seated body is 1.23 m tall and 1 m wide.
    Measured on the default body posed (T, A, arms down, legs together, seated, seated T) and the GarmentCode mean
    body: 1.0-2.65 for up, at most 0.17 for any other axis; with 90 % of the vertices dropped at random or the mesh
    clustered on a 5 cm grid, up still leads every other axis by 0.4 or more.
    """
    head, legs = _end_cues(np.asarray(vertices, dtype=np.float64))
    plus = head[:, 1] - head[:, 0] + _LEGS_WEIGHT * (legs[:, 0] - legs[:, 1])  # (3,) for +x, +y, +z
    return np.stack([plus, -plus], axis=1).ravel()


def _longest_side_up(vertices: np.ndarray) -> tuple[str, str]:
    """The fallback for shapes with no recognisable head and legs: the longest side, its sign from the ends (the
    lowest 5 % of a standing person holds two feet apart, wide across; the highest 5 % one narrow head)."""
    lo, hi = vertices.min(axis=0), vertices.max(axis=0)
    ext = hi - lo
    i = int(np.argmax(ext))
    h = vertices[:, i]
    across = np.delete(vertices, i, axis=1) / (ext[i] if ext[i] > 0 else 1.0)  # scaled: no overflow when squared

    def spread(mask: np.ndarray) -> float:
        pts = across[mask]
        return float(np.sqrt(((pts - pts.mean(axis=0)) ** 2).sum(axis=1).mean())) if len(pts) else 0.0

    low_end = spread(h <= lo[i] + 0.05 * ext[i])
    high_end = spread(h >= hi[i] - 0.05 * ext[i])
    name = ("+" if low_end >= high_end else "-") + "xyz"[i]
    return name, "the longest side, its wider end down"


def detect_up(vertices: np.ndarray) -> tuple[str, str]:
    """Guess the up axis ("+y", "-z", ...) of a body in any pose and say why.

    vertices : (V, 3) file units. The direction from the feet to the head wins (see `up_scores`); where no
    direction scores at least 0.3 (not a recognisable person), the longest side is taken.
    """
    vertices = np.asarray(vertices, dtype=np.float64)
    scores = up_scores(vertices)
    best = int(np.argmax(scores))
    # the runner-up on another axis: the opposite direction always scores -best
    rival = max((i for i in range(6) if i // 2 != best // 2), key=lambda i: scores[i])
    if not scores[best] >= _MIN_SCORE:
        name, why = _longest_side_up(vertices)
        return name, f"up axis {name}: no head over legs recognised (best score {scores[best]:.2f}); {why}"
    name = _DIRECTIONS[best]
    return name, (
        f"up axis {name}: one narrow head at the top, two legs at the bottom "
        f"(score {scores[best]:.2f}; next axis {_DIRECTIONS[rival]} {scores[rival]:.2f})"
    )


def head_size(vertices: np.ndarray, up_vec: np.ndarray) -> float | None:
    """The size across of the top 10 % of the body along `up_vec` (an axis vector), file units, if it looks like
    a head (`_head_likeness` > 0); None where it does not (raised hands, a shape that is no person)."""
    vertices = np.asarray(vertices, dtype=np.float64)
    k = int(np.argmax(np.abs(up_vec)))
    h = vertices @ up_vec
    length = float(np.ptp(h))
    if length <= 0.0:
        return None
    across = np.delete(vertices, k, axis=1).T.copy()  # (2, V)
    cue, size = _head_likeness(across, (h.max() - h) / length, length)
    return size if cue > 0.0 else None


def detect_units(height: float, head: float | None = None) -> str:
    """The unit a body is in, from its extent along up (`height`) and optionally its head's size, both file units.

    The height picks a unit in `UNIT_RANGES`: a person standing or seated is 0.3-3 m along up. One range is
    ambiguous: 30-100 units is a standing person in inches or, in centimetres, a seated adult (a 1.67 m person
    seated is 1.23 m tall, a 1.35 m one ~1 m) or a child. There the head decides: the unit that puts it nearer
    HEAD_SIZE_M (inches and centimetres differ 2.5x, more than heads do).
    """
    unit = next((u for u, low, high in UNIT_RANGES if low < height <= high), None)
    if unit is None:
        raise ValueError(f"height {height:g} fits no unit (expected a person 0.4-2.6 m tall in m, dm, in, cm or mm)")
    if unit == "in" and head is not None and head > 0.0:

        def miss(u: str) -> float:
            return abs(float(np.log(head * UNIT_SCALE[u] / HEAD_SIZE_M)))

        if miss("cm") < miss("in"):
            return "cm"
    return unit


def _rotation_to(up: np.ndarray, facing: np.ndarray) -> np.ndarray:
    """Proper rotation taking `up` to +Y and `facing` to +Z (both unit, orthogonal)."""
    x = np.cross(up, facing)  # becomes +X (the person's left when facing +Z with Y up)
    return np.stack([x, up, facing])  # rows: new axes expressed in old coordinates


def detect_facing(vertices: np.ndarray, up_vec: np.ndarray) -> tuple[str | None, str]:
    """Guess the forward axis from the feet, perpendicular to `up_vec` (an axis vector), and say why.

    vertices : (V, 3) file units. Along each axis across up, how far the feet (lowest 6 % of the height) stick out
    beyond the shins (12-22 %) on either side: toes stick out 8-12 % of the height in front, heels not at all
    behind (the calf reaches further back), standing or seated. Extremes rather than a centre: along the left-right
    axis the two legs stick out alike on both sides, whereas a median of two legs' vertices falls in one leg wherever
    the legs hold unequal vertex counts (a real scan, a decimated mesh) and read as 7-30 % there.
    """
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
        f, s = feet @ a, shins @ a
        gap = float((f.max() - s.max()) - (s.min() - f.min()))  # > 0: toes stick out along +a
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
            units = detect_units(height, head_size(vertices, up_vec))  # type: ignore[assignment]
        except ValueError as e:
            raise InputError(str(e), source) from None
        conv.notes.append(f"units {units}: height along up {height:g} file units = {height * UNIT_SCALE[units]:.3f} m")
    elif units not in UNIT_SCALE:
        raise InputError(f"units must be one of {', '.join(UNIT_SCALE)}, got {units!r}", source)
    conv.units, conv.scale = units, UNIT_SCALE[units]
    return conv
