"""The live mirror: camera frames in, the person wearing the kimono out, in a window, as fast as it goes.

Never behind the camera: the frames are read in their own thread and only the newest is taken (`frames.Latest`);
the pose of the next frame runs in a second thread while this one is simulated and drawn (MediaPipe leaves
Python's lock while it infers), so two cores work at once. The window shows the image flipped like a mirror,
with the frame rate; keys: `q` (or Esc) quits, `c` switches the correction on and off, `s` saves a snapshot.

The loop draws on a `Display`: `Window` (OpenCV's highgui) for people, or any object with the same two methods
(the tests use one that records frames and presses keys, with a video file paced like a camera).
"""

from __future__ import annotations

import os
import queue
import sys
import threading
import time
from dataclasses import replace
from pathlib import Path
from typing import Protocol

import numpy as np

from ..errors import InputError
from .frames import Latest, open_frames
from .mirror import TryOn, TryOnSettings
from .run import TryOnRun, source_info

#: The live mirror keeps the per-frame measures of this many last frames (counts cover all): flat memory.
LIVE_FRAMES_KEPT = 2000

_NO_DISPLAY = (
    "no display for the mirror window ({why}); run it on a desktop session, or write a video instead: "
    "kitsuke tryon SOURCE -o out.mp4"
)


class Display(Protocol):
    def show(self, rgb: np.ndarray) -> None:
        """Show one (H, W, 3) uint8 RGB image."""

    def key(self) -> str | None:
        """The key pressed since the last call, if any (one character; Esc as 'q')."""


class Window:
    """An OpenCV window. InputError when there is no display (no DISPLAY / WAYLAND_DISPLAY, or an OpenCV built
    without a GUI)."""

    def __init__(self, title: str = "kitsuke try-on") -> None:
        import cv2

        if os.name != "nt" and sys.platform != "darwin":
            # OpenCV's window is Qt on X11 (xcb): without a reachable X server Qt aborts the whole process
            why = _x_unreachable(os.environ.get("DISPLAY", ""))
            if why:
                raise InputError(_NO_DISPLAY.format(why=why))
        self.title = title
        try:
            cv2.namedWindow(title, cv2.WINDOW_NORMAL)
        except cv2.error as e:
            why = " ".join(str(e).split())[:160]
            raise InputError(_NO_DISPLAY.format(why=f"OpenCV cannot open a window: {why}")) from None
        self._cv2 = cv2

    def show(self, rgb: np.ndarray) -> None:
        self._cv2.imshow(self.title, self._cv2.cvtColor(rgb, self._cv2.COLOR_RGB2BGR))

    def key(self) -> str | None:
        k = self._cv2.waitKey(1) & 0xFF
        if k == 255:
            return None
        return "q" if k == 27 else chr(k)

    def close(self) -> None:
        self._cv2.destroyWindow(self.title)


def _x_unreachable(display: str) -> str | None:
    """Why the X display cannot be reached, or None when its socket answers."""
    import re
    import socket

    if not display:
        return "DISPLAY is not set (OpenCV's window needs X11; under Wayland, XWayland's DISPLAY)"
    m = re.fullmatch(r"(?P<host>[^:]*):(?P<num>\d+)(?:\.\d+)?", display)
    if m is None:
        return f"DISPLAY={display!r} is not a display name"
    host, num = m["host"], int(m["num"])
    try:
        if host in ("", "unix"):
            with socket.socket(socket.AF_UNIX) as s:
                s.settimeout(1.0)
                s.connect(f"/tmp/.X11-unix/X{num}")
        else:
            with socket.create_connection((host, 6000 + num), timeout=1.0):
                pass
    except OSError as e:
        return f"no X server answers on DISPLAY={display} ({e.strerror or e})"
    return None


def mirror_view(rgb: np.ndarray, fps: float, correcting: bool) -> np.ndarray:
    """The image as the window shows it: flipped left-right like a mirror, with the frame rate and whether the
    correction is on written in its corner."""
    import cv2

    out = np.ascontiguousarray(rgb[:, ::-1])
    text = f"{fps:4.1f} fps  correction {'on' if correcting else 'off'}  [q]uit [c]orrection [s]napshot"
    scale = max(0.35, rgb.shape[1] / 1400.0)
    for color, thick in (((0, 0, 0), 3), ((255, 255, 255), 1)):
        cv2.putText(out, text, (8, out.shape[0] - 10), cv2.FONT_HERSHEY_SIMPLEX, scale, color, thick, cv2.LINE_AA)
    return out


def run_live(
    source: str | os.PathLike[str] | int,
    display: Display,
    *,
    settings: TryOnSettings | None = None,
    constraints=None,  # noqa: ANN001
    garment=None,  # noqa: ANN001 - a kimono dressed on the default body (default: dressed now)
    snapshots: str | os.PathLike[str] = ".",
    max_seconds: float | None = None,
    paced: bool = True,
    on_snapshot=None,  # noqa: ANN001 - a callable taking the snapshot's Path
    on_frame=None,  # noqa: ANN001 - a callable taking each shown MirrorFrame and the TryOn (measures, recording)
) -> TryOnRun:
    """Run the mirror on `source` (a camera index, or a file played at its own rate) until `q`, the end of the
    source or `max_seconds`. Returns the run's measures (frames shown, dropped, latency per frame)."""
    from ..pose._mediapipe import _quiet_native_stderr

    settings = replace(settings or TryOnSettings(), recover=True)  # a mirror carries on: a failed kimono re-dressed
    src = open_frames(source)
    frames = Latest(src, paced=paced)
    run = TryOnRun(source_info(src), keep=LIVE_FRAMES_KEPT)
    observed: queue.Queue = queue.Queue(maxsize=1)
    stop = threading.Event()
    pace = _Pace()
    snap_dir = Path(snapshots)
    t0 = time.perf_counter()
    with _quiet_native_stderr(), TryOn(settings, garment=garment, constraints=constraints) as mirror:

        def hand_on(item: object) -> None:  # waits for the loop to take it, unless the loop has ended
            while not stop.is_set():
                try:
                    observed.put(item, timeout=0.1)
                    return
                except queue.Full:
                    continue

        def observe() -> None:  # the pose thread: the newest frame and its pose, handed to the loop
            it = iter(frames)
            try:
                while not stop.is_set():
                    # start the pose just in time for the loop's next frame: a pose done early would wait, and
                    # the frame it shows would be that much older when displayed
                    delay = pace.next_pose_in()
                    if delay > 0 and stop.wait(delay):
                        break
                    frame = next(it, None)
                    if frame is None:
                        break
                    seen = mirror.observe(frame)
                    pace.posed(seen.seconds)
                    hand_on((frame, seen))
            except BaseException as e:  # noqa: BLE001 - re-raised by the loop below
                hand_on(e)
            finally:
                hand_on(None)

        worker = threading.Thread(target=observe, name="kitsuke-pose", daemon=True)
        worker.start()
        shown: list[float] = []
        try:
            while True:
                item = observed.get()
                if item is None:
                    break
                if isinstance(item, BaseException):
                    raise item
                frame, seen = item
                pace.dressing()
                out = mirror.dress(frame, seen)
                now = time.perf_counter()
                shown.append(now)
                recent = [t for t in shown[-15:] if now - t < 2.0]
                fps = (len(recent) - 1) / (recent[-1] - recent[0]) if len(recent) > 1 else 0.0
                view = mirror_view(out.image, fps, mirror.correct)
                display.show(view)
                if on_frame is not None:
                    on_frame(out, mirror)
                run.add(out, frame.arrived)
                key = display.key()
                if key == "q":
                    break
                if key == "c":
                    mirror.correct = not mirror.correct
                if key == "s":
                    path = _snapshot(snap_dir, view)
                    if on_snapshot is not None:
                        on_snapshot(path)
                pace.dressed()
                if max_seconds is not None and now - t0 > max_seconds:
                    break
        finally:
            stop.set()
            frames.stop()
            worker.join(timeout=5.0)
    run.wall_s = time.perf_counter() - t0
    run.dropped = frames.dropped
    run.skipped, run.ended = src.skipped, src.ended
    return run


class _Pace:
    """When the pose thread should take the next frame: as the loop, which began a frame at `start`, will be done
    with it `pose_s` later (running means of both stages' times). Shared by two threads: floats are written whole."""

    def __init__(self) -> None:
        self.pose_s = 0.0
        self.dress_s = 0.0
        self.start: float | None = None

    def posed(self, seconds: float) -> None:
        self.pose_s = seconds if self.pose_s == 0.0 else 0.8 * self.pose_s + 0.2 * seconds

    def dressing(self) -> None:
        self.start = time.perf_counter()

    def dressed(self) -> None:
        if self.start is not None:
            took = time.perf_counter() - self.start
            self.dress_s = took if self.dress_s == 0.0 else 0.8 * self.dress_s + 0.2 * took

    def next_pose_in(self) -> float:
        """Seconds to wait before taking the next frame (0: now)."""
        if self.start is None:
            return 0.0
        return self.start + self.dress_s - self.pose_s - time.perf_counter()


def _snapshot(folder: Path, rgb: np.ndarray) -> Path:
    from PIL import Image

    folder.mkdir(parents=True, exist_ok=True)
    path = folder / time.strftime("kitsuke-tryon-%Y%m%d-%H%M%S.png")
    k = 1
    while path.exists():
        path = folder / time.strftime(f"kitsuke-tryon-%Y%m%d-%H%M%S-{k}.png")
        k += 1
    Image.fromarray(rgb).save(path)
    return path
