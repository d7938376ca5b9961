"""One entry point for every pose source: video, image, image folder, camera, BVH, kitsuke poses JSON."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Literal

from ..errors import InputError
from ._bvh_map import load_bvh
from ._filter import OneEuroConfig, filter_poses
from ._sequence import PoseSequence, read_poses

SourceKind = Literal["video", "image", "images", "camera", "bvh", "poses"]


def source_kind(source: str | os.PathLike[str] | int) -> SourceKind:
    """What a source is: an int is a camera index; a folder holds images; otherwise the file suffix decides
    (.bvh, .json, image suffixes), and anything else is tried as a video."""
    from ._mediapipe import IMAGE_SUFFIXES

    if isinstance(source, int):
        return "camera"
    p = Path(source)
    if p.is_dir():
        return "images"
    suffix = p.suffix.lower()
    if suffix == ".bvh":
        return "bvh"
    if suffix == ".json":
        return "poses"
    if suffix in IMAGE_SUFFIXES:
        return "image"
    return "video"


def load_poses(
    source: str | os.PathLike[str] | int,
    *,
    filter: OneEuroConfig | bool | None = None,
    stride: int = 1,
    max_frames: int | None = None,
    start_s: float = 0.0,
    fps: float = 30.0,
    scale: float | None = None,
    seconds: float | None = None,
) -> PoseSequence:
    """Poses from any source (see `source_kind`), in the SPEC §2 joint set, metres, Y up.

    Parameters
    ----------
    filter : One-Euro settings, True for the defaults, False for none; None (default) filters video and camera
        sources only (BVH, JSON and still images are used as they are).
    stride, max_frames : every `stride`-th frame, at most `max_frames` of them (video, BVH).
    start_s : skip the first seconds of a video.
    fps : frame rate given to a folder of images.
    scale : metres per BVH unit (default: from the skeleton's height).
    seconds : stop a camera after this long (default: until Ctrl-C or `max_frames`).
    """
    kind = source_kind(source)
    if kind == "camera":
        from ._mediapipe import extract_camera

        poses = extract_camera(int(source), max_frames=max_frames, seconds=seconds)
    elif kind == "images":
        from ._mediapipe import extract_images

        poses = extract_images(source, fps=fps)  # type: ignore[arg-type]
    elif kind == "image":
        from ._mediapipe import extract_images

        poses = extract_images(source, fps=fps)  # type: ignore[arg-type]
    elif kind == "bvh":
        poses = load_bvh(source, scale=scale, stride=stride, max_frames=max_frames)  # type: ignore[arg-type]
    elif kind == "poses":
        poses = read_poses(source)  # type: ignore[arg-type]
    else:
        from ._mediapipe import extract_video

        poses = extract_video(source, stride=stride, max_frames=max_frames, start_s=start_s)  # type: ignore[arg-type]
    if filter is None:
        filter = kind in ("video", "camera")
    if filter is True:
        filter = OneEuroConfig()
    if isinstance(filter, OneEuroConfig) and filter.enabled:
        poses = filter_poses(poses, filter)
    elif filter not in (False, None) and not isinstance(filter, OneEuroConfig):
        raise InputError(f"filter must be a OneEuroConfig, True or False, got {filter!r}")
    return poses
