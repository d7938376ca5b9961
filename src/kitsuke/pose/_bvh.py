"""BVH motion capture files: a parser (hierarchy, channels in any rotation order, frames) and forward kinematics.

Conventions of the format as read here:
- A joint's local rotation is the product of its rotation channels in the order they are listed
  (`Zrotation Xrotation Yrotation` → R = Rz·Rx·Ry, acting on column vectors), angles in degrees.
- The root's position channels give its position (they replace its OFFSET, as Blender and most exporters do).
- Position channels on other joints: files differ. Some write the joint's full local position (the OFFSET plus
  any motion, Blender-style exports), others only a displacement added to the OFFSET (MakeHuman writes zeros).
  `read_bvh` tells them apart per file: if those channels' values are closer to the joints' OFFSETs than to zero
  they replace the OFFSET, otherwise they are added to it.
"""

from __future__ import annotations

import math
import os
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .. import limits
from .._files import require_file
from ..errors import InputError

_CHANNELS = ("Xposition", "Yposition", "Zposition", "Xrotation", "Yrotation", "Zrotation")


@dataclass
class BvhFile:
    """The content of a BVH file, in the file's own units and axes.

    Attributes
    ----------
    names : joint names (J), in file order; parents come before children.
    parents : (J,) int64, parent index, -1 for the root.
    offsets : (J, 3) float64, file units: each joint's rest position relative to its parent.
    channels : per joint, its channel names in file order (e.g. ("Zrotation", "Xrotation", "Yrotation")).
    end_offsets : (E, 3) float64, file units: the End Site points relative to their joint.
    end_parents : (E,) int64, the joint each End Site belongs to.
    frame_time : seconds per frame.
    motion : (n, C) float64: channel values per frame, C = total channel count, in joint/channel order.
    position_channels_replace_offset : how non-root position channels are read (see the module docstring).
    """

    names: list[str]
    parents: np.ndarray
    offsets: np.ndarray
    channels: list[tuple[str, ...]]
    end_offsets: np.ndarray
    end_parents: np.ndarray
    frame_time: float
    motion: np.ndarray
    position_channels_replace_offset: bool = False

    @property
    def n_frames(self) -> int:
        return len(self.motion)

    @property
    def fps(self) -> float:
        """Frames per second, rounded to 3 decimals when the frame time is a rounded 1/fps (0.0333333 → 30)."""
        f = 1.0 / self.frame_time
        return round(f) if abs(f - round(f)) < 1e-3 * f else f

    def channel_columns(self) -> list[np.ndarray]:
        """Per joint, the columns of `motion` that hold its channels."""
        cols, start = [], 0
        for ch in self.channels:
            cols.append(np.arange(start, start + len(ch)))
            start += len(ch)
        return cols


def _axis_rotations(axis: str, angles_deg: np.ndarray) -> np.ndarray:
    """(n, 3, 3) rotation matrices about a coordinate axis."""
    a = np.deg2rad(angles_deg)
    c, s = np.cos(a), np.sin(a)
    n = len(a)
    r = np.zeros((n, 3, 3))
    i = "XYZ".index(axis)
    j, k = (i + 1) % 3, (i + 2) % 3
    r[:, i, i] = 1.0
    r[:, j, j] = c
    r[:, k, k] = c
    r[:, k, j] = s
    r[:, j, k] = -s
    return r


def read_bvh(path: str | os.PathLike[str]) -> BvhFile:
    """Parse a BVH file; InputError naming the file and the problem (bad hierarchy, truncated motion, NaN)."""
    p = require_file(path, what="BVH file")
    try:
        text = p.read_text(encoding="utf-8", errors="replace")
    except OSError as e:
        raise InputError(f"cannot read BVH file: {e.strerror}", p) from None
    head, sep, motion_text = text.partition("MOTION")
    if not sep or "HIERARCHY" not in head:
        raise InputError("not a BVH file (needs a HIERARCHY and a MOTION section)", p)
    names: list[str] = []
    parents: list[int] = []
    offsets: list[list[float]] = []
    channels: list[tuple[str, ...]] = []
    end_offsets: list[list[float]] = []
    end_parents: list[int] = []
    stack: list[int] = []  # joint index per open brace; -2 for an End Site block
    pending: int | None = None  # the joint (or -2) whose "{" is expected next
    lines = head.split("HIERARCHY", 1)[1].splitlines()
    for lineno, raw in enumerate(lines, start=2):
        line = raw.strip()
        if not line:
            continue
        opens = line.endswith("{") and line != "{"
        if opens:
            line = line[:-1].strip()
        word, _, rest = line.partition(" ")
        rest = rest.strip()
        try:
            if word in ("ROOT", "JOINT"):
                if word == "ROOT" and names:
                    # A second skeleton in the same file: kitsuke reads the first one only.
                    break
                if word == "JOINT" and (not stack or stack[-1] < 0):
                    raise InputError(f"line {lineno}: JOINT outside a joint", p)
                names.append(rest or f"joint{len(names)}")
                parents.append(stack[-1] if stack else -1)
                offsets.append([0.0, 0.0, 0.0])
                channels.append(())
                pending = len(names) - 1
            elif word == "End":
                if not stack or stack[-1] < 0:
                    raise InputError(f"line {lineno}: End Site outside a joint", p)
                end_parents.append(stack[-1])
                end_offsets.append([0.0, 0.0, 0.0])
                pending = -2
            elif word == "{" or opens:
                if pending is None:
                    raise InputError(f"line {lineno}: unexpected '{{'", p)
                stack.append(pending)
                pending = None
            elif word == "}":
                if not stack:
                    raise InputError(f"line {lineno}: unbalanced '}}'", p)
                stack.pop()
            elif word == "OFFSET":
                vals = [float(v) for v in rest.split()[:3]]
                if len(vals) != 3 or not all(math.isfinite(v) for v in vals):
                    raise InputError(f"line {lineno}: OFFSET needs 3 finite numbers", p)
                if stack and stack[-1] == -2:
                    end_offsets[-1] = vals
                elif stack:
                    offsets[stack[-1]] = vals
            elif word == "CHANNELS":
                parts = rest.split()
                count = int(parts[0])
                chans = tuple(parts[1 : 1 + count])
                if len(chans) != count or any(c not in _CHANNELS for c in chans):
                    raise InputError(f"line {lineno}: bad CHANNELS list {rest!r}", p)
                if not stack or stack[-1] < 0:
                    raise InputError(f"line {lineno}: CHANNELS outside a joint", p)
                channels[stack[-1]] = chans
            else:
                raise InputError(f"line {lineno}: unexpected {word!r} in HIERARCHY", p)
        except InputError:
            raise
        except ValueError:  # float()/int() of something that is not a number
            raise InputError(f"line {lineno}: bad number in {line!r}", p) from None
        if opens:
            if pending is None:
                raise InputError(f"line {lineno}: unexpected '{{'", p)
            stack.append(pending)
            pending = None
    if not names:
        raise InputError("BVH file has no ROOT joint", p)
    if stack:
        # Braces still open at MOTION: the hierarchy was cut short.
        raise InputError("HIERARCHY ends with unclosed braces (truncated file?)", p)

    m_frames = re.search(r"Frames:\s*(\d+)", motion_text)
    m_time = re.search(r"Frame Time:\s*([0-9.eE+-]+)", motion_text)
    if not m_frames or not m_time:
        raise InputError("MOTION section needs 'Frames:' and 'Frame Time:'", p)
    n = int(m_frames.group(1))
    try:
        frame_time = float(m_time.group(1))
    except ValueError:
        raise InputError(f"bad Frame Time {m_time.group(1)!r}", p) from None
    if not (frame_time > 0 and math.isfinite(frame_time)):
        raise InputError(f"Frame Time must be positive, got {frame_time}", p)
    if n <= 0:
        raise InputError("the file has no frames (Frames: 0)", p)
    limits.check("frames", n, f"the file has {n:,} frames", p)
    data_text = motion_text[m_time.end() :]
    n_ch = sum(len(c) for c in channels)
    try:
        values = np.array(data_text.split(), dtype=np.float64)
    except ValueError:
        raise InputError("MOTION data holds something that is not a number", p) from None
    if n_ch == 0:
        raise InputError("no joint has CHANNELS", p)
    if len(values) < n * n_ch:
        got = len(values) // n_ch
        raise InputError(f"truncated MOTION data: 'Frames: {n}' but only {got} full frames of {n_ch} values", p)
    motion = values[: n * n_ch].reshape(n, n_ch)
    if not np.isfinite(motion).all():
        bad = int(np.flatnonzero(~np.isfinite(motion).all(axis=1))[0])
        raise InputError(f"MOTION frame {bad} has NaN or infinite values", p)

    bvh = BvhFile(
        names=names,
        parents=np.array(parents, dtype=np.int64),
        offsets=np.array(offsets, dtype=np.float64).reshape(-1, 3),
        channels=channels,
        end_offsets=np.array(end_offsets, dtype=np.float64).reshape(-1, 3),
        end_parents=np.array(end_parents, dtype=np.int64),
        frame_time=frame_time,
        motion=motion,
    )
    bvh.position_channels_replace_offset = _position_channels_replace(bvh)
    return bvh


def _position_channels_replace(bvh: BvhFile) -> bool:
    """True when the non-root position channels hold full local positions (values near the OFFSETs)."""
    diffs, mags = [], []
    for j, (ch, cols) in enumerate(zip(bvh.channels, bvh.channel_columns(), strict=True)):
        if bvh.parents[j] < 0:
            continue
        for axis in range(3):
            name = "XYZ"[axis] + "position"
            if name in ch:
                v = bvh.motion[:, cols[ch.index(name)]]
                diffs.append(np.abs(v - bvh.offsets[j, axis]).mean())
                mags.append(np.abs(v).mean())
    if not diffs:
        return False
    return float(np.sum(diffs)) < float(np.sum(mags))


def forward_kinematics(
    bvh: BvhFile, frames: np.ndarray | None = None, *, rest: bool = False
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """World positions and rotations of every joint and End Site, file units and axes.

    Parameters
    ----------
    frames : frame indices to evaluate (default all).
    rest : evaluate the rest pose instead (all channels zero, root at the origin): one frame.

    Returns
    -------
    positions : (n, J, 3) float64, file units.
    rotations : (n, J, 3, 3) float64, each joint's world rotation (column vectors).
    end_positions : (n, E, 3) float64, file units.
    """
    if rest:
        values = np.zeros((1, bvh.motion.shape[1]))
    else:
        values = bvh.motion if frames is None else bvh.motion[np.asarray(frames)]
    n = len(values)
    n_j = len(bvh.names)
    pos = np.zeros((n, n_j, 3))
    rot = np.zeros((n, n_j, 3, 3))
    for j, (ch, cols) in enumerate(zip(bvh.channels, bvh.channel_columns(), strict=True)):
        local_r = np.broadcast_to(np.eye(3), (n, 3, 3)).copy()
        local_t = np.broadcast_to(bvh.offsets[j], (n, 3)).copy()
        is_root = bvh.parents[j] < 0
        for name, col in zip(ch, cols, strict=True):
            axis = "XYZ".index(name[0])
            if name.endswith("rotation"):
                local_r = local_r @ _axis_rotations(name[0], values[:, col])
            elif rest:
                continue
            elif is_root or bvh.position_channels_replace_offset:
                local_t[:, axis] = values[:, col]
            else:
                local_t[:, axis] += values[:, col]
        if rest and is_root:
            local_t[:] = 0.0
        par = bvh.parents[j]
        if par < 0:
            rot[:, j] = local_r
            pos[:, j] = local_t
        else:
            rot[:, j] = rot[:, par] @ local_r
            pos[:, j] = pos[:, par] + np.einsum("nij,nj->ni", rot[:, par], local_t)
    end = pos[:, bvh.end_parents] + np.einsum("neij,ej->nei", rot[:, bvh.end_parents], bvh.end_offsets)
    return pos, rot, end


def bvh_summary(path: str | os.PathLike[str]) -> str:
    """One line about a BVH file (joints, frames, fps), for messages."""
    b = read_bvh(path)
    return f"{Path(path).name}: {len(b.names)} joints, {b.n_frames} frames at {b.fps:g} fps"
