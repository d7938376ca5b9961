"""Where the try-on's frames come from: a video file, a folder of images, or a camera, scaled to a working size.

`open_frames(source)` gives a `FrameSource`: iterate it for `Frame`s in order (a file: every frame; a camera:
as it delivers them). `Latest` runs a source in a thread and hands out only the newest frame, dropping the rest:
the live mirror's way of never building latency. A file played through `Latest(paced=True)` arrives at its own
frame rate, as from a camera (the headless stand-in the tests use).

Bad frames do not stop a run: an image that does not decode is skipped and counted (`FrameSource.skipped`); a
camera that stops delivering ends the run with `FrameSource.ended` saying so.
"""

from __future__ import annotations

import os
import threading
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import InputError

#: The working size the try-on scales frames down to: longer side, shorter side (pixels). Pose, simulation and
#: render all run at this size; 640x480 is what the live targets are stated for.
WORKING_SIZE = (640, 480)
#: Frames per second of an image folder, unless told.
FOLDER_FPS = 30.0


@dataclass(frozen=True)
class Frame:
    """index : the frame's number in its source (counting dropped and skipped ones). time_s : its time, seconds
    (a file: index / fps; a camera: since the first frame). rgb : (H, W, 3) uint8 at the working size.
    arrived : `time.perf_counter()` when it was read (latency is measured from here)."""

    index: int
    time_s: float
    rgb: np.ndarray
    arrived: float


def working_size(size: tuple[int, int], limit: tuple[int, int] = WORKING_SIZE) -> tuple[int, int]:
    """(width, height) scaled down (never up) so that the longer side fits limit[0] and the shorter limit[1];
    both even (H.264)."""
    w, h = size
    long_side, short_side = (w, h) if w >= h else (h, w)
    s = min(1.0, limit[0] / long_side, limit[1] / short_side)
    return max(2, int(round(w * s / 2)) * 2), max(2, int(round(h * s / 2)) * 2)


class FrameSource:
    """Frames of one source at the working size. name : for messages. size : working (width, height).
    fps : the source's frame rate (a camera: what it reports, else 30). total : frames expected, None if unknown.
    live : a camera (frames come in real time). skipped : frames that did not decode. ended : why the source
    ended early, or None."""

    def __init__(self, name: str, size: tuple[int, int], fps: float, total: int | None, live: bool) -> None:
        self.name = name
        self.size = size
        self.fps = fps
        self.total = total
        self.live = live
        self.skipped = 0
        self.ended: str | None = None

    def _bgr_frames(self) -> Iterator[tuple[int, float, np.ndarray | None]]:  # pragma: no cover - abstract
        raise NotImplementedError

    def __iter__(self) -> Iterator[Frame]:
        import cv2

        for index, t, bgr in self._bgr_frames():
            if bgr is None:
                self.skipped += 1
                continue
            if (bgr.shape[1], bgr.shape[0]) != self.size:
                bgr = cv2.resize(bgr, self.size, interpolation=cv2.INTER_AREA)
            yield Frame(index, t, cv2.cvtColor(bgr, cv2.COLOR_BGR2RGB), time.perf_counter())


class _Video(FrameSource):
    def __init__(self, path: Path, limit: tuple[int, int]) -> None:
        from ..pose._mediapipe import open_video

        self._cap, fps, n, size = open_video(path)
        super().__init__(str(path), working_size(size, limit), fps, n or None, live=False)

    def _bgr_frames(self) -> Iterator[tuple[int, float, np.ndarray | None]]:
        i = 0
        try:
            while True:
                ok, bgr = self._cap.read()
                if not ok:
                    if self.total is not None and i < self.total:
                        self.ended = f"the video ends after {i} of its {self.total} frames (cut short or corrupt)"
                    return
                yield i, i / self.fps, bgr
                i += 1
        finally:
            self._cap.release()


class _Folder(FrameSource):
    def __init__(self, folder: Path, limit: tuple[int, int], fps: float) -> None:
        from ..pose._mediapipe import _read_size, image_files

        self._files = image_files(folder)
        super().__init__(str(folder), working_size(_read_size(self._files[0]), limit), fps, len(self._files), False)

    def _bgr_frames(self) -> Iterator[tuple[int, float, np.ndarray | None]]:
        from ..pose._mediapipe import _read_image

        for i, path in enumerate(self._files):
            try:
                bgr = _read_image(path)
            except InputError:
                bgr = None  # a corrupt image is one lost frame, not the end of the run
            yield i, i / self.fps, bgr


class _Camera(FrameSource):
    def __init__(self, index: int, limit: tuple[int, int]) -> None:
        import cv2

        self._cap = cv2.VideoCapture(int(index))
        if not self._cap.isOpened():
            raise InputError("cannot open the camera (no camera with this index, or it is in use)", f"camera {index}")
        size = (int(self._cap.get(cv2.CAP_PROP_FRAME_WIDTH)), int(self._cap.get(cv2.CAP_PROP_FRAME_HEIGHT)))
        fps = float(self._cap.get(cv2.CAP_PROP_FPS) or 0.0)
        super().__init__(f"camera {index}", working_size(size, limit), fps if 0 < fps < 1000 else 30.0, None, True)

    def _bgr_frames(self) -> Iterator[tuple[int, float, np.ndarray | None]]:
        t0 = time.perf_counter()
        i = 0
        try:
            while True:
                ok, bgr = self._cap.read()
                if not ok:
                    self.ended = f"the camera stopped giving frames after {i} frames (unplugged or taken?)"
                    return
                yield i, time.perf_counter() - t0, bgr
                i += 1
        finally:
            self._cap.release()


def open_frames(
    source: str | os.PathLike[str] | int, *, limit: tuple[int, int] = WORKING_SIZE, fps: float = FOLDER_FPS
) -> FrameSource:
    """A video file, a folder of images (at `fps`) or a camera (an int index). InputError names the source when
    it cannot be opened."""
    if isinstance(source, int):
        return _Camera(source, limit)
    path = Path(source)
    if path.is_dir():
        return _Folder(path, limit, fps)
    return _Video(path, limit)


class Latest:
    """A source read in its own thread, handing out only the newest frame (older ones are dropped and counted).

    paced : deliver a file's frames at its frame rate in wall time, as a camera would (the headless stand-in for
    a camera). Iterate for frames; `dropped` counts the frames never handed out; `stop()` ends the reader.
    """

    def __init__(self, source: FrameSource, *, paced: bool = False) -> None:
        self.source = source
        self.dropped = 0
        self._paced = paced and not source.live
        self._frame: Frame | None = None
        self._done = False
        self._stop = threading.Event()
        self._ready = threading.Condition()
        self._thread = threading.Thread(target=self._read, name="kitsuke-frames", daemon=True)
        self._thread.start()

    def _read(self) -> None:
        t0 = time.perf_counter()
        try:
            for frame in self.source:
                if self._stop.is_set():
                    return
                if self._paced:
                    wait = t0 + frame.time_s - time.perf_counter()
                    if wait > 0:
                        time.sleep(wait)
                    frame = Frame(frame.index, frame.time_s, frame.rgb, time.perf_counter())
                with self._ready:
                    if self._frame is not None:
                        self.dropped += 1
                    self._frame = frame
                    self._ready.notify()
        finally:
            with self._ready:
                self._done = True
                self._ready.notify()

    def __iter__(self) -> Iterator[Frame]:
        while True:
            with self._ready:
                while self._frame is None and not self._done:
                    self._ready.wait(0.5)
                frame, self._frame = self._frame, None
                if frame is None:
                    return
            yield frame

    def stop(self) -> None:
        self._stop.set()
        self._thread.join(timeout=2.0)
