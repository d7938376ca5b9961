"""The arms of a standing body, as straight axes found from its mesh alone (no rig needed): where a place on the
body is an armpit, a shoulder or an upper arm (`kitsuke.body.regions`), also for a body loaded without a rig.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..geometry import TriMesh
from ..geometry.section import section_parts


@dataclass(frozen=True)
class ArmAxis:
    """One arm as a straight line down its upper arm and forearm.

    start : (3,) float64 metres, the axis where the arm leaves the torso (the armpit's height).
    direction : (3,) unit vector from the shoulder towards the hand.
    length_m : how far down the arm the axis was measured, metres (the upper arm).
    radius_m : the arm's median radius round the axis, metres.
    hand_m : how far along the axis the arm ends (its lowest cross-section, the fingertips), metres.
    """

    start: np.ndarray
    direction: np.ndarray
    length_m: float
    radius_m: float
    hand_m: float = 0.0

    def distance(self, points: np.ndarray) -> np.ndarray:
        """(N,) metres: each point's distance (N, 3) from the axis as an infinite line."""
        rel = points - self.start
        return np.linalg.norm(rel - np.outer(rel @ self.direction, self.direction), axis=1)


def arm_axes(
    mesh: TriMesh,
    *,
    step_m: float = 0.02,
    max_width_m: float = 0.2,
    reach_m: float = 0.3,
    bend_m: float = 0.01,
) -> dict[str, ArmAxis]:
    """The arms of `mesh` (metres, Y up, the person's left at +x, standing with the arms away from the torso: an
    A-pose or arms hanging apart from the sides), keyed "left" and "right"; an arm not found is left out (a T-pose,
    arms touching the torso, a body without arms).

    Every `step_m` down from the shoulders, the body is cut by a horizontal plane (`section_parts`). Where the cut
    has three or more separate parts, the outermost on each side is that arm when narrower than `max_width_m`. The
    axis is the least-squares line through those parts' centres over at most `reach_m` of height below the armpit,
    down to where they bend more than `bend_m` off it (`_upper_arm`: the elbow); a sleeve closes round the upper
    arm at the armpit."""
    v = mesh.vertices
    y0, height = float(v[:, 1].min()), float(np.ptp(v[:, 1]))
    centres: dict[str, list[np.ndarray]] = {"left": [], "right": []}
    points: dict[str, list[np.ndarray]] = {"left": [], "right": []}
    lowest: dict[str, np.ndarray] = {}
    for y in np.arange(y0 + 0.85 * height, y0 + 0.35 * height, -step_m):
        parts = [part for part in section_parts(v, mesh.faces, float(y)) if len(part) >= 6]
        if len(parts) < 3:
            continue
        parts.sort(key=lambda part: part[:, 0].mean())
        for side, arm in (("right", parts[0]), ("left", parts[-1])):
            seen = centres[side]
            if np.ptp(arm[:, 0]) > max_width_m:
                continue
            lowest[side] = arm.mean(axis=0)
            if seen and seen[0][1] - y > reach_m:
                continue
            seen.append(arm.mean(axis=0))
            points[side].append(arm)
    axes = {}
    for side, seen in centres.items():
        c = _upper_arm(np.array(seen), bend_m)
        if c is None:
            continue
        mean = c.mean(axis=0)
        direction = _line(c)
        start = mean + ((c[0] - mean) @ direction) * direction
        axis = ArmAxis(start, direction, float((c[-1] - c[0]) @ direction), 0.0)
        axes[side] = replace(
            axis,
            radius_m=float(np.median(axis.distance(np.concatenate(points[side][: len(c)])))),
            hand_m=max(float((lowest[side] - start) @ direction), axis.length_m),
        )
    return axes


def _line(centres: np.ndarray) -> np.ndarray:
    """The unit direction of the least-squares line through `centres` (n, 3), pointing down."""
    direction = np.linalg.svd(centres - centres.mean(axis=0))[2][0]
    return -direction if direction[1] > 0 else direction


def _upper_arm(centres: np.ndarray, bend_m: float) -> np.ndarray | None:
    """The first of an arm's cross-section `centres` (n, 3), from the armpit down, that lie on one straight line:
    up to the first that falls more than `bend_m` off the line through those before it (the elbow's bend; a
    forearm held forward drew the default body's axis 21 degrees off its upper arm bone). None: fewer than 3."""
    if len(centres) < 3:
        return None
    n = len(centres)
    for k in range(4, len(centres)):
        line = centres[:k]
        direction = _line(line)
        rel = centres[k] - line.mean(axis=0)
        if np.linalg.norm(rel - (rel @ direction) * direction) > bend_m:
            n = k
            break
    return centres[:n]
