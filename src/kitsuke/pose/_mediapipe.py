"""Poses from pixels: MediaPipe `PoseLandmarker` (Tasks API) on video files, images, image folders and cameras.

The model ships inside the package (assets/models/, see its NOTICE.md); nothing is downloaded. mediapipe and
OpenCV (`cv2`, from mediapipe's opencv-contrib-python dependency) are imported only when a function here runs.
A frame with no person gives `valid = False`; it never raises.
"""

from __future__ import annotations

import contextlib
import os
import sys
import time
from collections.abc import Iterator
from importlib import resources
from pathlib import Path
from typing import Any, Literal

import numpy as np

from .. import limits
from .._files import require_file
from .._prefetch import prefetch
from .._progress import progress
from ..errors import InputError
from ..skeleton import JOINTS
from ._landmarks import image_to_joints, world_to_joints
from ._sequence import PoseSequence

MODEL_FILE = "pose_landmarker_full.task"
MODEL_NAME = "MediaPipe pose_landmarker_full (BlazePose GHUM 3D full)"
IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".bmp", ".webp", ".tif", ".tiff")
VIDEO_SUFFIXES = (".mp4", ".mov", ".avi", ".mkv", ".webm", ".m4v", ".mpg", ".mpeg")


@contextlib.contextmanager
def model_path() -> Iterator[Path]:
    """The packaged pose model bundle as a file path (valid inside the `with`)."""
    ref = resources.files("kitsuke") / "assets" / "models" / MODEL_FILE
    with resources.as_file(ref) as p:
        if not p.is_file():
            raise InputError("the pose model is missing from the kitsuke installation", p)
        yield p


@contextlib.contextmanager
def _quiet_native_stderr() -> Iterator[None]:
    """Silence what MediaPipe's C++ side prints (TFLite/absl INFO and W0000 lines) while Python keeps its stderr.

    File descriptor 2 points at /dev/null for the duration, and `sys.stderr` writes to a duplicate of the original
    descriptor, so progress bars and Python messages still show. Errors still surface as Python exceptions.
    """
    try:
        fd = sys.stderr.fileno()
    except (AttributeError, OSError, ValueError):  # stderr replaced (pytest capture): nothing to silence
        yield
        return
    if fd != 2:
        yield
        return
    sys.stderr.flush()
    saved = os.dup(2)
    devnull = os.open(os.devnull, os.O_WRONLY)
    old_stderr = sys.stderr
    os.dup2(devnull, 2)
    sys.stderr = open(saved, "w", buffering=1, closefd=False, encoding=old_stderr.encoding, errors="replace")
    try:
        yield
    finally:
        sys.stderr.flush()
        sys.stderr = old_stderr
        os.dup2(saved, 2)
        os.close(saved)
        os.close(devnull)


def _cv2() -> Any:
    os.environ.setdefault("OPENCV_FFMPEG_LOGLEVEL", "-8")  # ffmpeg's own messages ("moov atom not found")
    import cv2

    cv2.utils.logging.setLogLevel(cv2.utils.logging.LOG_LEVEL_SILENT)
    return cv2


class PoseLandmarker:
    """A MediaPipe pose landmarker with the packaged model; use as a context manager.

    Parameters
    ----------
    mode : "video" (frames of one sequence, tracked; timestamps must increase) or "image" (independent images).
    min_detection_confidence, min_presence_confidence, min_tracking_confidence : MediaPipe's thresholds, in [0, 1].
    num_poses : how many people to look for (`detect_all`); `detect` gives the most prominent.
    """

    def __init__(
        self,
        mode: Literal["video", "image"] = "video",
        *,
        min_detection_confidence: float = 0.5,
        min_presence_confidence: float = 0.5,
        min_tracking_confidence: float = 0.5,
        num_poses: int = 1,
    ):
        if mode not in ("video", "image"):
            raise ValueError(f"mode must be 'video' or 'image', got {mode!r}")
        self.mode = mode
        self.num_poses = int(num_poses)
        self._opts = (min_detection_confidence, min_presence_confidence, min_tracking_confidence)
        self._landmarker: Any = None
        self._stack = contextlib.ExitStack()
        self._last_ms = -1

    def __enter__(self) -> PoseLandmarker:
        from mediapipe.tasks.python import BaseOptions, vision

        path = self._stack.enter_context(model_path())
        running = vision.RunningMode.VIDEO if self.mode == "video" else vision.RunningMode.IMAGE
        options = vision.PoseLandmarkerOptions(
            base_options=BaseOptions(model_asset_path=str(path)),
            running_mode=running,
            num_poses=self.num_poses,
            min_pose_detection_confidence=self._opts[0],
            min_pose_presence_confidence=self._opts[1],
            min_tracking_confidence=self._opts[2],
        )
        self._landmarker = vision.PoseLandmarker.create_from_options(options)
        return self

    def __exit__(self, *exc: object) -> None:
        if self._landmarker is not None:
            self._landmarker.close()
            self._landmarker = None
        self._stack.close()

    def detect(self, rgb: np.ndarray, timestamp_ms: int | None = None) -> tuple[np.ndarray, np.ndarray] | None:
        """Landmarks of the most prominent person in an RGB frame, or None when there is nobody.

        Parameters
        ----------
        rgb : (H, W, 3) uint8 RGB image.
        timestamp_ms : the frame's time in milliseconds (video mode; must increase from call to call).

        Returns
        -------
        (world, image): (33, 3) float64 MediaPipe world landmarks (metres, hip-centred, y down, z away from the
        camera) and (33, 3) float64 pixels u, v with visibility in [0, 1].
        """
        people = self.detect_all(rgb, timestamp_ms)
        return people[0] if people else None

    def detect_all(self, rgb: np.ndarray, timestamp_ms: int | None = None) -> list[tuple[np.ndarray, np.ndarray]]:
        """Landmarks of up to `num_poses` people, as `detect` gives them for one (an empty list for nobody)."""
        import mediapipe as mp

        if self._landmarker is None:
            raise RuntimeError("use PoseLandmarker as a context manager")
        frame = mp.Image(image_format=mp.ImageFormat.SRGB, data=np.ascontiguousarray(rgb))
        if self.mode == "video":
            ms = int(timestamp_ms if timestamp_ms is not None else self._last_ms + 1)
            ms = max(ms, self._last_ms + 1)  # MediaPipe refuses equal or decreasing timestamps
            self._last_ms = ms
            result = self._landmarker.detect_for_video(frame, ms)
        else:
            result = self._landmarker.detect(frame)
        h, w = rgb.shape[:2]
        people = []
        for world_lm, image_lm in zip(result.pose_world_landmarks, result.pose_landmarks, strict=False):
            world = np.array([[p.x, p.y, p.z] for p in world_lm], dtype=np.float64)
            image = np.array(
                [[p.x * w, p.y * h, p.visibility if p.visibility is not None else 0.0] for p in image_lm],
                dtype=np.float64,
            )
            if world.shape == (33, 3) and image.shape == (33, 3) and np.isfinite(world).all():
                people.append((world, image))
        return people


def _collect(
    frames: Iterator[tuple[float, np.ndarray]],
    *,
    total: int | None,
    mode: Literal["video", "image"],
    desc: str,
    stop_on_interrupt: bool = False,
    **landmarker_options: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, list[tuple[int, int]]]:
    """Run the landmarker over (time s, BGR frame) pairs; returns times, valid, positions, image points, sizes.

    With `stop_on_interrupt`, Ctrl-C ends the run and keeps what was processed (live cameras)."""
    cv2 = _cv2()
    nan = np.full((len(JOINTS), 3), np.nan)
    rows: list[tuple[float, tuple[int, int], bool, np.ndarray, np.ndarray]] = []
    with _quiet_native_stderr(), PoseLandmarker(mode, **landmarker_options) as lm:  # type: ignore[arg-type]
        try:
            for t, bgr in progress(frames, total=total, desc=desc):
                rgb = cv2.cvtColor(bgr, cv2.COLOR_BGR2RGB)
                found = lm.detect(rgb, int(round(t * 1000.0)))
                size = (bgr.shape[1], bgr.shape[0])
                if found is None:
                    rows.append((t, size, False, nan, nan))
                else:
                    rows.append((t, size, True, world_to_joints(found[0]), image_to_joints(found[1])))
        except KeyboardInterrupt:
            if not stop_on_interrupt:
                raise
    n = len(rows)
    shape = (n, len(JOINTS), 3)
    return (
        np.array([r[0] for r in rows], dtype=np.float64),
        np.array([r[2] for r in rows], dtype=bool),
        np.array([r[3] for r in rows], dtype=np.float64).reshape(shape),
        np.array([r[4] for r in rows], dtype=np.float64).reshape(shape),
        [r[1] for r in rows],
    )


def open_video(path: str | os.PathLike[str]) -> tuple[Any, float, int, tuple[int, int]]:
    """Open a video file with OpenCV: (capture, fps, declared frame count, (width, height)); InputError when it
    cannot be decoded (not a video, or truncated so that its index is gone)."""
    p = require_file(path, what="video file")
    cv2 = _cv2()
    cap = cv2.VideoCapture(str(p))
    if not cap.isOpened():
        raise InputError("cannot open the video (not a video file, or truncated/corrupt)", p)
    fps = float(cap.get(cv2.CAP_PROP_FPS) or 0.0)
    n = int(cap.get(cv2.CAP_PROP_FRAME_COUNT) or 0)
    size = (int(cap.get(cv2.CAP_PROP_FRAME_WIDTH)), int(cap.get(cv2.CAP_PROP_FRAME_HEIGHT)))
    if not (fps > 0 and np.isfinite(fps)):
        fps = 30.0  # containers without a frame rate: assume 30 and say so in the source
    try:
        limits.check_image(*size, p)
        limits.check("frames", n, f"the video declares {n:,} frames", p)
    except InputError:
        cap.release()
        raise
    return cap, fps, n, size


def extract_video(
    path: str | os.PathLike[str],
    *,
    stride: int = 1,
    max_frames: int | None = None,
    start_s: float = 0.0,
    **landmarker_options: float,
) -> PoseSequence:
    """Poses from a video file (VIDEO mode).

    Parameters
    ----------
    stride : process every `stride`-th frame (times stay the frames' real times).
    max_frames : stop after this many processed frames.
    start_s : skip the video's first seconds.

    The result's `source` records the video's size, frame rate and frame count; a file that ends before its
    declared frame count (cut short) is processed as far as it decodes and marked `"truncated": true`.
    InputError when the file cannot be opened or has no decodable frame.
    """
    if stride < 1:
        raise InputError(f"stride must be at least 1, got {stride}", path)
    cap, fps, declared, size = open_video(path)
    first = int(round(max(0.0, start_s) * fps))
    decoded = [0]

    def frames() -> Iterator[tuple[float, np.ndarray]]:
        i, kept = 0, 0
        try:
            while max_frames is None or kept < max_frames:
                if i < first or (i - first) % stride:
                    ok = cap.grab()
                    frame = None
                else:
                    ok, frame = cap.read()
                if not ok:
                    return
                decoded[0] = i + 1
                if frame is not None:
                    kept += 1
                    yield i / fps, frame
                i += 1
        finally:
            cap.release()

    wanted = max(0, declared - first + stride - 1) // stride if declared > 0 else None
    if wanted is not None and max_frames is not None:
        wanted = min(wanted, max_frames)
    # decoding runs a few frames ahead in a thread (OpenCV releases the GIL): it overlaps the inference
    times, valid, pos, img, _ = _collect(
        prefetch(frames()), total=wanted, mode="video", desc="pose", **landmarker_options
    )
    if len(times) == 0:
        raise InputError("the video has no decodable frames (empty or corrupt)", path)
    source: dict[str, Any] = {
        "kind": "video",
        "path": str(path),
        "size": [size[0], size[1]],
        "fps": fps,
        "frames": declared,
        "stride": stride,
        "model": MODEL_NAME,
    }
    reached_end = max_frames is None or len(times) < max_frames
    if reached_end and declared > 0 and decoded[0] < declared:
        source["truncated"] = True
        source["frames_decoded"] = decoded[0]
    return PoseSequence(positions=pos, valid=valid, times=times, fps=fps / stride, source=source, image=img)


def _read_image(path: Path) -> np.ndarray:
    try:  # the header's size, before decoding a picture that would not fit in memory
        from PIL import Image

        with Image.open(path) as im:
            size = im.size
    except Exception:  # noqa: BLE001 - not an image Pillow knows: OpenCV decides below
        size = None
    if size is not None:
        limits.check_image(*size, path)
    cv2 = _cv2()
    data = np.fromfile(str(path), dtype=np.uint8)
    bgr = cv2.imdecode(data, cv2.IMREAD_COLOR) if data.size else None
    if bgr is None:
        raise InputError("cannot read the image (not an image file, or corrupt)", path)
    return bgr


def image_files(folder: str | os.PathLike[str]) -> list[Path]:
    """The image files of a folder, sorted by name; InputError when there are none."""
    d = Path(folder)
    if not d.is_dir():
        raise InputError("not a folder", d)
    files = sorted(p for p in d.iterdir() if p.suffix.lower() in IMAGE_SUFFIXES and p.is_file())
    if not files:
        raise InputError(f"no images ({', '.join(IMAGE_SUFFIXES)}) in the folder", d)
    return files


def extract_images(
    source: str | os.PathLike[str] | list[str | os.PathLike[str]],
    *,
    fps: float = 30.0,
    **landmarker_options: float,
) -> PoseSequence:
    """Poses from one image, a list of images or a folder of images (sorted by name).

    A single image, or images of different sizes, run in IMAGE mode (each on its own); images of one size are
    taken as the frames of a sequence at `fps` and run in VIDEO mode (tracked, as from a video).
    """
    if not (fps > 0):
        raise InputError(f"fps must be positive, got {fps}")
    if isinstance(source, (list, tuple)):
        files = [require_file(p, what="image") for p in source]
        kind, where = "images", [str(p) for p in source]
    elif Path(source).is_dir():
        files = image_files(source)
        kind, where = "images", str(source)
    else:
        files = [require_file(source, what="image")]
        kind, where = "image", str(source)
    images = [_read_image(p) for p in files] if len(files) <= 1 else None
    sizes = {(_read_size(p)) for p in files} if images is None else {images[0].shape[1::-1]}
    mode: Literal["video", "image"] = "video" if len(files) > 1 and len(sizes) == 1 else "image"

    def frames() -> Iterator[tuple[float, np.ndarray]]:
        for i, p in enumerate(files):
            yield i / fps, (images[i] if images is not None else _read_image(p))

    times, valid, pos, img, frame_sizes = _collect(
        frames(), total=len(files), mode=mode, desc="pose", **landmarker_options
    )
    src: dict[str, Any] = {"kind": kind, "path": where, "mode": mode, "model": MODEL_NAME}
    if len(set(frame_sizes)) == 1:
        src["size"] = list(frame_sizes[0])
    else:
        src["sizes"] = [list(s) for s in frame_sizes]
    if kind == "images":
        src["files"] = [p.name for p in files]
    return PoseSequence(positions=pos, valid=valid, times=times, fps=fps, source=src, image=img)


def _read_size(path: Path) -> tuple[int, int]:
    """(width, height) of an image without decoding all of it when Pillow can tell."""
    try:
        from PIL import Image

        with Image.open(path) as im:
            size = im.size
    except Exception:  # noqa: BLE001 - fall back to a full decode, which raises InputError if unreadable
        bgr = _read_image(path)
        return bgr.shape[1], bgr.shape[0]
    limits.check_image(*size, path)
    return size


def extract_camera(
    index: int = 0,
    *,
    max_frames: int | None = None,
    seconds: float | None = None,
    **landmarker_options: float,
) -> PoseSequence:
    """Poses from a live camera (VIDEO mode, real timestamps) until `max_frames`, `seconds` or Ctrl-C.

    InputError naming the camera when it cannot be opened (no camera, or in use). Frames are not mirrored here.
    """
    cv2 = _cv2()
    where = f"camera {index}"
    cap = cv2.VideoCapture(int(index))
    if not cap.isOpened():
        raise InputError("cannot open the camera (no camera with this index, or it is in use)", where)
    size = (int(cap.get(cv2.CAP_PROP_FRAME_WIDTH)), int(cap.get(cv2.CAP_PROP_FRAME_HEIGHT)))
    t0 = time.monotonic()

    def frames() -> Iterator[tuple[float, np.ndarray]]:
        n = 0
        try:
            while max_frames is None or n < max_frames:
                t = time.monotonic() - t0
                if seconds is not None and t > seconds:
                    return
                ok, frame = cap.read()
                if not ok:
                    return
                n += 1
                yield time.monotonic() - t0, frame
        except KeyboardInterrupt:  # Ctrl-C ends the recording; what was captured is kept
            return
        finally:
            cap.release()

    times, valid, pos, img, _ = _collect(
        frames(), total=max_frames, mode="video", desc="camera", stop_on_interrupt=True, **landmarker_options
    )
    if len(times) == 0:
        raise InputError("the camera gave no frames", where)
    fps = (len(times) - 1) / (times[-1] - times[0]) if len(times) > 1 and times[-1] > times[0] else 30.0
    src = {"kind": "camera", "path": where, "size": list(size), "model": MODEL_NAME}
    return PoseSequence(positions=pos, valid=valid, times=times, fps=float(fps), source=src, image=img)
