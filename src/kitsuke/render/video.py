"""H.264 mp4 files written frame by frame (ffmpeg from imageio-ffmpeg, in its own process), atomically."""

from __future__ import annotations

import os
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Protocol

import numpy as np

from .._files import atomic_path


class FrameSink(Protocol):
    def __call__(self, rgb: np.ndarray) -> None: ...


@contextmanager
def mp4_writer(path: str | os.PathLike[str], size: tuple[int, int], fps: float) -> Iterator[FrameSink]:
    """Write an H.264 mp4 (yuv420p, faststart) of (height, width, 3) uint8 RGB frames of `size` (width, height),
    both even, at `fps`: `with mp4_writer(p, (w, h), 30) as send: send(frame)`. The file appears at `path` only
    when the block ends without an error."""
    import imageio_ffmpeg

    params = ["-preset", "veryfast", "-crf", "23", "-movflags", "+faststart", "-f", "mp4"]
    with atomic_path(path) as tmp:
        writer = imageio_ffmpeg.write_frames(
            str(tmp),
            size,
            fps=float(fps),
            codec="libx264",
            quality=None,
            macro_block_size=2,
            output_params=params,
            ffmpeg_log_level="error",
        )
        writer.send(None)
        try:
            yield lambda rgb: writer.send(np.ascontiguousarray(rgb))
        finally:
            writer.close()
    return Path(path)  # type: ignore[return-value]
