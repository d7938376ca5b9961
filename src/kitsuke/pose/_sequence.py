"""`PoseSequence`: poses over time in the SPEC §2 joint set, and the `kitsuke.poses` v1 JSON file (SPEC §3.4)."""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from .. import limits
from .._files import read_json, write_json_atomic
from ..errors import InputError
from ..skeleton import INDEX, JOINTS

FORMAT = "kitsuke.poses"
VERSION = 1


@dataclass
class PoseSequence:
    """A person's joint positions over time.

    Attributes
    ----------
    positions : (n, 23, 3) float64, metres, Y up, the person facing +Z with their left at +X (SPEC §2).
        Joint order is `kitsuke.skeleton.JOINTS`. Rows of invalid frames are NaN.
    valid : (n,) bool, False where no person was found (those frames have no positions).
    times : (n,) float64, seconds from the start, non-decreasing.
    fps : frames per second of the sequence (after any frame skipping).
    source : where the poses came from (`kind`: video | image | images | camera | bvh | poses, `path`, `size`
        [width, height] in pixels for images, `fps` of the original video, ...). Written to the file as is.
    image : (n, 23, 3) float64 or None: pixel u (right), v (down) and visibility in [0, 1] of each joint in its
        frame, for image and video sources; NaN for invalid frames.
    raw_positions : (n, 23, 3) float64 or None: the positions before posture correction (corrected files only).
    corrected : list of n tuples of joint names or None: per frame, the target joints whose segment was rotated
        by the posture correction (SPEC §5.3); empty tuple where nothing was changed (corrected files only).
    constraints : the constraint table used by the correction (`kitsuke.pose.ConstraintTable`) or None.
    """

    positions: np.ndarray
    valid: np.ndarray
    times: np.ndarray
    fps: float
    source: dict[str, Any] = field(default_factory=dict)
    image: np.ndarray | None = None
    raw_positions: np.ndarray | None = None
    corrected: list[tuple[str, ...]] | None = None
    constraints: Any = None

    joints: tuple[str, ...] = field(default=JOINTS, init=False)

    def __post_init__(self) -> None:
        self.positions = np.array(self.positions, dtype=np.float64).reshape(-1, len(JOINTS), 3)
        n = len(self.positions)
        self.valid = np.asarray(self.valid, dtype=bool).reshape(-1)
        self.times = np.asarray(self.times, dtype=np.float64).reshape(-1)
        if len(self.valid) != n or len(self.times) != n:
            raise ValueError(f"valid ({len(self.valid)}) and times ({len(self.times)}) must have {n} entries")
        if not (self.fps > 0 and math.isfinite(self.fps)):
            raise ValueError(f"fps must be positive, got {self.fps}")
        # Invalid frames carry no positions: keep them NaN so nothing uses stale numbers by accident.
        self.positions[~self.valid] = np.nan
        if self.valid.any() and not np.isfinite(self.positions[self.valid]).all():
            raise ValueError("valid frames must have finite positions")
        for name in ("image", "raw_positions"):
            arr = getattr(self, name)
            if arr is not None:
                arr = np.array(arr, dtype=np.float64).reshape(n, len(JOINTS), 3)
                setattr(self, name, arr)
        if self.corrected is not None:
            if len(self.corrected) != n:
                raise ValueError(f"corrected has {len(self.corrected)} entries for {n} frames")
            self.corrected = [tuple(c) for c in self.corrected]

    @property
    def n_frames(self) -> int:
        return len(self.positions)

    def joint(self, name: str) -> np.ndarray:
        """(n, 3) float64 positions of one joint over time, metres."""
        return self.positions[:, INDEX[name]]

    def copy(self) -> PoseSequence:
        """A deep copy (arrays copied)."""
        return replace(
            self,
            positions=self.positions.copy(),
            valid=self.valid.copy(),
            times=self.times.copy(),
            source=dict(self.source),
            image=None if self.image is None else self.image.copy(),
            raw_positions=None if self.raw_positions is None else self.raw_positions.copy(),
            corrected=None if self.corrected is None else list(self.corrected),
        )

    def subset(self, frames: np.ndarray | slice) -> PoseSequence:
        """The sequence restricted to some frames (indices, mask or slice); times are kept as they are."""
        idx = np.arange(self.n_frames)[frames]
        return replace(
            self,
            positions=self.positions[idx],
            valid=self.valid[idx],
            times=self.times[idx],
            source=dict(self.source),
            image=None if self.image is None else self.image[idx],
            raw_positions=None if self.raw_positions is None else self.raw_positions[idx],
            corrected=None if self.corrected is None else [self.corrected[i] for i in idx],
        )


# --------------------------------------------------------------------------------------------------- writing


def _rows(arr: np.ndarray, digits: int) -> list[list[float]]:
    return np.round(arr, digits).tolist()


def poses_to_json(poses: PoseSequence) -> dict[str, Any]:
    """The `kitsuke.poses` v1 document of a sequence (a JSON-ready dict).

    Positions are written exactly (shortest round-trip floats), so reading the file back gives the same numbers;
    pixels are rounded to 1e-3 px and visibility to 1e-4.
    """
    doc: dict[str, Any] = {
        "format": FORMAT,
        "version": VERSION,
        "units": "m",
        "up": [0, 1, 0],
        "fps": float(poses.fps),
        "source": poses.source,
        "joints": list(JOINTS),
    }
    if poses.constraints is not None:
        doc["constraints"] = poses.constraints.to_json()
    frames = []
    for i in range(poses.n_frames):
        fr: dict[str, Any] = {"t": round(float(poses.times[i]), 9), "valid": bool(poses.valid[i])}
        if poses.valid[i]:
            # repr-exact floats: a file round trip must give back the same numbers (the SPEC's "untouched
            # frames are identical to the input" is checked on files too).
            fr["positions"] = poses.positions[i].tolist()
            if poses.raw_positions is not None:
                fr["raw_positions"] = poses.raw_positions[i].tolist()
            if poses.image is not None and np.isfinite(poses.image[i]).all():
                img = poses.image[i]
                fr["image"] = [[round(u, 3), round(v, 3), round(s, 4)] for u, v, s in img.tolist()]
        if poses.corrected is not None:
            fr["corrected"] = list(poses.corrected[i])
        frames.append(fr)
    doc["frames"] = frames
    return doc


def write_poses(poses: PoseSequence, path: str | os.PathLike[str]) -> Path:
    """Write a `kitsuke.poses` v1 JSON file atomically; returns the path."""
    return write_json_atomic(path, poses_to_json(poses))


# --------------------------------------------------------------------------------------------------- reading


def _number(x: Any) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool)


def _joint_array(value: Any, order: np.ndarray, what: str, path: Path) -> np.ndarray:
    """A (23, 3) array from a list of per-joint triples in the file's joint order; InputError naming `what`."""
    if not isinstance(value, list):
        raise InputError(f"{what} must be a list of [x, y, z] per joint", path)
    if len(value) != len(order):
        raise InputError(f"{what} has {len(value)} joints, expected {len(order)} (one per name in 'joints')", path)
    for i, v in enumerate(value):
        if not isinstance(v, list) or len(v) != 3:
            raise InputError(f"{what}: joint {JOINTS[order[i]]} needs a list of 3 numbers", path)
    try:
        arr = np.array(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise InputError(f"{what} must hold numbers only, as [x, y, z] per joint", path) from None
    if arr.shape != (len(order), 3):
        raise InputError(f"{what} must be a list of {len(order)} triples, got shape {arr.shape}", path)
    bad = ~np.isfinite(arr).all(axis=1)
    if bad.any():
        names = [JOINTS[order[i]] for i in np.flatnonzero(bad)[:5]]
        raise InputError(f"{what} has NaN or infinite values at joint(s) {', '.join(names)}", path)
    out = np.empty((len(JOINTS), 3))
    out[order] = arr
    return out


def poses_from_json(doc: Any, path: str | os.PathLike[str] = "<poses>") -> PoseSequence:
    """Validate a parsed `kitsuke.poses` v1 document and build the sequence; InputError naming `path` and what."""
    from ._constraints import ConstraintTable

    p = Path(path)
    if not isinstance(doc, dict) or doc.get("format") != FORMAT:
        raise InputError(f'not a {FORMAT} file (missing "format": "{FORMAT}")', p)
    if doc.get("version") != VERSION:
        raise InputError(f"unsupported {FORMAT} version {doc.get('version')!r}; this kitsuke reads {VERSION}", p)
    if doc.get("units", "m") != "m":
        raise InputError(f'units must be "m", got {doc.get("units")!r}', p)
    if doc.get("up", [0, 1, 0]) != [0, 1, 0]:
        raise InputError(f"up must be [0, 1, 0] (Y up), got {doc.get('up')!r}", p)
    fps = doc.get("fps")
    if not _number(fps) or not (math.isfinite(fps) and fps > 0):
        raise InputError(f"fps must be a positive number, got {fps!r}", p)
    joints = doc.get("joints")
    if not isinstance(joints, list) or not all(isinstance(j, str) for j in joints):
        raise InputError("joints must be a list of joint names", p)
    unknown = [j for j in joints if j not in INDEX]
    if unknown:
        raise InputError(
            f"unknown joint name(s) {', '.join(map(repr, unknown[:5]))}; joints are {', '.join(JOINTS)}", p
        )
    missing = [j for j in JOINTS if j not in joints]
    if missing:
        raise InputError(f"missing joint(s) {', '.join(missing)} in 'joints'", p)
    if len(set(joints)) != len(joints):
        raise InputError("joints lists a name twice", p)
    order = np.array([INDEX[j] for j in joints])
    frames = doc.get("frames")
    if not isinstance(frames, list) or not frames:
        raise InputError("frames must be a non-empty list", p)
    limits.check("frames", len(frames), f"the file has {len(frames):,} frames", p)
    source = doc.get("source", {})
    if not isinstance(source, dict):
        raise InputError("source must be an object", p)

    n = len(frames)
    positions = np.full((n, len(JOINTS), 3), np.nan)
    valid = np.zeros(n, dtype=bool)
    times = np.zeros(n)
    has_image = any(isinstance(f, dict) and "image" in f for f in frames)
    has_raw = any(isinstance(f, dict) and "raw_positions" in f for f in frames)
    has_corr = any(isinstance(f, dict) and "corrected" in f for f in frames)
    image = np.full((n, len(JOINTS), 3), np.nan) if has_image else None
    raw = np.full((n, len(JOINTS), 3), np.nan) if has_raw else None
    corrected: list[tuple[str, ...]] | None = [()] * n if has_corr else None
    for i, fr in enumerate(frames):
        where = f"frame {i}"
        if not isinstance(fr, dict):
            raise InputError(f"{where} must be an object", p)
        t = fr.get("t")
        if not _number(t) or not math.isfinite(t):
            raise InputError(f"{where}: t must be a number of seconds, got {t!r}", p)
        if i and t < times[i - 1]:
            raise InputError(f"{where}: t = {t} goes back in time (previous {times[i - 1]})", p)
        times[i] = t
        v = fr.get("valid", "positions" in fr)
        if not isinstance(v, bool):
            raise InputError(f"{where}: valid must be true or false", p)
        valid[i] = v
        if not v:
            continue
        if "positions" not in fr:
            raise InputError(f"{where}: valid frame without positions", p)
        positions[i] = _joint_array(fr["positions"], order, f"{where}: positions", p)
        if "raw_positions" in fr and raw is not None:
            raw[i] = _joint_array(fr["raw_positions"], order, f"{where}: raw_positions", p)
        elif raw is not None:
            raise InputError(f"{where}: raw_positions missing (other frames have them)", p)
        if "image" in fr and image is not None:
            image[i] = _joint_array(fr["image"], order, f"{where}: image", p)
        if corrected is not None:
            c = fr.get("corrected", [])
            if not isinstance(c, list) or any(j not in INDEX for j in c):
                raise InputError(f"{where}: corrected must be a list of joint names", p)
            corrected[i] = tuple(c)
    if not valid.any():
        # A file of only invalid frames is legal (a clip with nobody in it); nothing downstream divides by it.
        pass
    constraints = None
    if "constraints" in doc:
        constraints = ConstraintTable.from_json(doc["constraints"], p)
    return PoseSequence(
        positions=positions,
        valid=valid,
        times=times,
        fps=float(fps),
        source=source,
        image=image,
        raw_positions=raw,
        corrected=corrected,
        constraints=constraints,
    )


def read_poses(path: str | os.PathLike[str]) -> PoseSequence:
    """Read and validate a `kitsuke.poses` v1 JSON file; InputError naming the file and what is wrong."""
    return poses_from_json(read_json(path, what="poses file"), path)
