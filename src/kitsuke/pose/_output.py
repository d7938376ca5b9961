"""What `kitsuke pose correct` shows: a plot of the leg distances against the kimono's limit, and an overlay video
(raw skeleton in grey, corrected one in colour, with a legend; or raw | corrected side by side) as H.264 mp4.

On video frames the raw skeleton is what was detected: MediaPipe's 2D landmarks, drawn as they are. The corrected
one is the same points plus each joint's 3D correction projected into the image: per frame an affine camera (2×4
matrix M, [u, v] = M·[X, Y, Z, 1]) is fitted by least squares from the raw 3D joints to their detected points,
weighted by visibility, and the correction offsets go through its linear part. Joints the correction did not move
stay exactly on their detections, so a poor fit (MediaPipe's world coordinates are hip-centred and metric, its
image points perspective) can only misplace the corrected offsets, not the skeleton; the fit's residual is
measured and reported.
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np

from .._files import atomic_path
from .._prefetch import prefetch
from .._progress import progress
from ..errors import InputError
from ..render.video import mp4_writer
from ..skeleton import BONES, INDEX, JOINTS, descendants
from ._constraints import PAIRS
from ._correct import Correction, regions_of

_BONES = np.array([[INDEX[a], INDEX[b]] for a, b in BONES])
_LEFT = np.array([j.startswith("l_") for j in JOINTS])
_RIGHT = np.array([j.startswith("r_") for j in JOINTS])


def fit_affine_camera(world: np.ndarray, image: np.ndarray, weights: np.ndarray | None = None) -> np.ndarray:
    """(2, 4) affine camera M with [u, v] ≈ M·[X, Y, Z, 1], by weighted least squares.

    Parameters
    ----------
    world : (J, 3) float64 joint positions, metres.  image : (J, 2) float64 pixels.
    weights : (J,) float64 ≥ 0, e.g. visibility (default all 1); joints with weight 0 are ignored.
    """
    w = np.ones(len(world)) if weights is None else np.clip(np.asarray(weights, dtype=np.float64), 0.0, None)
    a = np.column_stack([world, np.ones(len(world))]) * np.sqrt(w)[:, None]
    b = image * np.sqrt(w)[:, None]
    m, *_ = np.linalg.lstsq(a, b, rcond=None)
    return m.T


def _project(m: np.ndarray, pts: np.ndarray) -> np.ndarray:
    return pts @ m[:, :3].T + m[:, 3]


# ----------------------------------------------------------------------------------------------------- plot


def plot_distances(correction: Correction, path: str | os.PathLike[str], *, title: str | None = None) -> Path:
    """PNG of the horizontal knee and ankle distances over time, raw and corrected, against the limit E(θ)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    poses = correction.poses
    table = poses.constraints
    raw = poses.raw_positions
    if table is None or raw is None:
        raise ValueError("plot_distances needs a corrected sequence")
    t = poses.times
    fig, axes = plt.subplots(2, 1, figsize=(10, 6.2), sharex=True, dpi=110)
    for ax, (i, name) in zip(axes, enumerate(PAIRS), strict=True):
        jl, jr = INDEX[f"l_{name}"], INDEX[f"r_{name}"]
        d_raw = np.linalg.norm(raw[:, jr, ::2] - raw[:, jl, ::2], axis=1)
        d_cor = np.linalg.norm(poses.positions[:, jr, ::2] - poses.positions[:, jl, ::2], axis=1)
        _, excess = regions_of(poses.positions, table, name)
        limit = d_cor - excess
        rot = correction.rotated[:, i]
        for f in np.flatnonzero(rot):
            ax.axvspan(t[f] - 0.5 / poses.fps, t[f] + 0.5 / poses.fps, color="#f6d7a7", lw=0, zorder=0)
        ax.plot(t, d_raw * 100, color="0.55", lw=1.6, label="raw")
        ax.plot(t, d_cor * 100, color="#1f5fbf", lw=1.6, label="corrected")
        ax.plot(t, limit * 100, color="#c0392b", lw=1.2, ls="--", label="limit E(θ) of the corrected pose")
        ax.set_ylabel(f"{name} distance (cm)")
        ax.grid(alpha=0.3)
        n_rot = int(rot.sum())
        ax.set_title(f"{name}s: horizontal distance between left and right — {n_rot} frame(s) corrected", fontsize=10)
    axes[0].legend(loc="upper right", fontsize=8)
    axes[-1].set_xlabel("time (s)")
    label = title or str(poses.source.get("path", ""))
    fig.suptitle(f"kimono posture correction ({table.source}): {label}", fontsize=10)
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png")
    plt.close(fig)
    return Path(path)


# ----------------------------------------------------------------------------------------------------- video


def _source_frames(poses: Any, base_dir: Path | None) -> tuple[Iterator[np.ndarray | None], tuple[int, int]] | None:
    """Frames (BGR) for each pose frame from the sequence's video or image files, or None when there are none."""
    from ._mediapipe import _read_image, open_video

    src = poses.source
    kind, where = src.get("kind"), src.get("path")
    if kind not in ("video", "image", "images") or where is None or poses.image is None:
        return None
    p = Path(where)
    if not p.exists() and base_dir is not None and (base_dir / p).exists():
        p = base_dir / p
    if not p.exists():
        return None
    if kind == "video":
        cap, fps, _, size = open_video(p)
        src_fps = float(src.get("fps", fps))

        def frames() -> Iterator[np.ndarray | None]:
            i, frame = -1, None
            try:
                for t in poses.times:
                    want = int(round(t * src_fps))
                    while i < want:
                        ok, frame = cap.read()
                        if not ok:
                            frame = None
                            break
                        i += 1
                    yield frame
            finally:
                cap.release()

        return frames(), size
    files = [p] if kind == "image" else [p / f for f in src.get("files", [])]
    if len(files) != poses.n_frames:
        return None
    first = _read_image(files[0])
    return (_read_image(f) for f in files), (first.shape[1], first.shape[0])


def _draw_skeleton(
    cv2: Any,
    img: np.ndarray,
    uv: np.ndarray,
    colours: dict[str, tuple[int, int, int]],
    thick: int,
    highlight: set[int] = frozenset(),
) -> None:  # type: ignore[assignment]
    for a, b in _BONES:
        if not (np.isfinite(uv[a]).all() and np.isfinite(uv[b]).all()):
            continue
        side = "l" if _LEFT[b] else "r" if _RIGHT[b] else "c"
        col = colours["hot"] if b in highlight else colours[side]
        cv2.line(img, tuple(int(x) for x in uv[a]), tuple(int(x) for x in uv[b]), col, thick, cv2.LINE_AA)
    for j in range(len(uv)):
        if np.isfinite(uv[j]).all():
            col = colours["hot"] if j in highlight else colours["joint"]
            cv2.circle(img, tuple(int(x) for x in uv[j]), max(2, thick), col, -1, cv2.LINE_AA)


GREY = {
    "l": (150, 150, 150),
    "r": (150, 150, 150),
    "c": (150, 150, 150),
    "joint": (150, 150, 150),
    "hot": (150, 150, 150),
}
COLOUR = {
    "l": (235, 140, 40),
    "r": (60, 170, 250),
    "c": (90, 200, 90),
    "joint": (255, 255, 255),
    "hot": (40, 40, 230),
}  # BGR: left blue, right orange, rotated segments red


def _views(poses: Any, width: int, height: int) -> tuple[float, np.ndarray]:
    """Scale (px per m) and per-frame pelvis for the synthetic front + top views."""
    both = np.concatenate([poses.positions, poses.raw_positions], axis=1)
    pelvis = poses.positions[:, INDEX["pelvis"]]
    rel = both - pelvis[:, None, :]
    ext = np.nanmax(np.abs(rel[poses.valid]), axis=(0, 1)) if poses.valid.any() else np.ones(3)
    half_w = width / 4.0
    scale = 0.85 * min(half_w / max(ext[0], ext[2], 0.3), (height / 2.0) / max(ext[1], 0.3))
    return scale, pelvis


def _synthetic_frame(
    cv2: Any,
    poses: Any,
    f: int,
    size: tuple[int, int],
    scale: float,
    pelvis: np.ndarray,
    correction: Correction,
    highlight: set[int],
) -> np.ndarray:
    w, h = size
    img = np.full((h, w, 3), 32, dtype=np.uint8)
    cv2.line(img, (w // 2, 0), (w // 2, h), (70, 70, 70), 1)
    cv2.putText(img, "front", (10, 22), cv2.FONT_HERSHEY_SIMPLEX, 0.6, (200, 200, 200), 1, cv2.LINE_AA)
    cv2.putText(
        img, "top (front down)", (w // 2 + 10, 22), cv2.FONT_HERSHEY_SIMPLEX, 0.6, (200, 200, 200), 1, cv2.LINE_AA
    )
    if not poses.valid[f]:
        return img
    c = pelvis[f]

    def front(p: np.ndarray) -> np.ndarray:  # viewer at +Z: the person's left (+X) on the image's right
        return np.column_stack([w / 4 + (p[:, 0] - c[0]) * scale, h / 2 - (p[:, 1] - c[1]) * scale])

    def top(p: np.ndarray) -> np.ndarray:  # seen from above, the person's front (+Z) toward the image's bottom
        return np.column_stack([3 * w / 4 + (p[:, 0] - c[0]) * scale, h / 2 + (p[:, 2] - c[2]) * scale])

    for name, col in (("knee", (120, 220, 120)), ("ankle", (120, 200, 240))):
        ell, _ = regions_of(poses.positions[f : f + 1], poses.constraints, name)
        e = ell[0]
        t = np.linspace(0, 2 * np.pi, 72)
        pts = np.column_stack(
            [
                e[0] + e[4] * np.cos(t) * e[2] + e[5] * np.sin(t) * e[3],
                np.zeros_like(t),
                e[1] + e[4] * np.cos(t) * e[3] - e[5] * np.sin(t) * e[2],
            ]
        )
        cv2.polylines(img, [top(pts).astype(np.int32)], True, col, 1, cv2.LINE_AA)
    for proj in (front, top):
        _draw_skeleton(cv2, img, proj(poses.raw_positions[f]), GREY, 5)
        _draw_skeleton(cv2, img, proj(poses.positions[f]), COLOUR, 2, highlight)
    return img


def _legend(cv2: Any, img: np.ndarray, lines: list[tuple[str, tuple[int, int, int]]], origin=(10, 10)) -> None:
    """A small legend box: one coloured line sample and its label per entry."""
    x0, y0 = origin
    h = 22 * len(lines) + 8
    w = 12 + 30 + 8 + max(cv2.getTextSize(t, cv2.FONT_HERSHEY_SIMPLEX, 0.5, 1)[0][0] for t, _ in lines) + 10
    box = img[y0 : y0 + h, x0 : x0 + w]
    box[:] = (0.45 * box).astype(np.uint8)  # darken behind the text, keep the frame visible
    for i, (text, col) in enumerate(lines):
        y = y0 + 18 + 22 * i
        cv2.line(img, (x0 + 12, y - 5), (x0 + 42, y - 5), col, 4, cv2.LINE_AA)
        cv2.putText(img, text, (x0 + 50, y), cv2.FONT_HERSHEY_SIMPLEX, 0.5, (255, 255, 255), 1, cv2.LINE_AA)


LEGEND = [
    ("raw pose", GREY["l"]),
    ("corrected: left", COLOUR["l"]),
    ("corrected: right", COLOUR["r"]),
    ("rotated by the correction", COLOUR["hot"]),
]
LEGEND_SIDE = [("left", COLOUR["l"]), ("right", COLOUR["r"]), ("rotated by the correction", COLOUR["hot"])]


def image_skeletons(poses: Any, f: int, scale: float = 1.0) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """Frame f's skeletons in the image: (raw (J, 2) px: the detected landmarks, corrected (J, 2) px, the affine
    camera's residual (J,) px on the joints seen with visibility ≥ 0.5, NaN elsewhere), at `scale` times the
    source's pixels; None without a detection.

    The corrected skeleton starts from what was seen: each joint's detected point plus its 3D correction
    (corrected − raw, metres) projected by the linear part of an affine camera fitted to that frame's detected
    points; joints the correction did not move stay exactly on their detections.
    """
    if not poses.valid[f] or poses.image is None or not np.isfinite(poses.image[f, :, :2]).all():
        return None
    uv = poses.image[f, :, :2] * scale
    vis = poses.image[f, :, 2]
    raw3d = poses.raw_positions[f]
    m = fit_affine_camera(raw3d, uv, vis)
    corrected = uv + (poses.positions[f] - raw3d) @ m[:, :3].T
    residual = np.linalg.norm(_project(m, raw3d) - uv, axis=1) / scale
    residual[vis < 0.5] = np.nan
    return uv, corrected, residual


def write_overlay_video(
    correction: Correction,
    path: str | os.PathLike[str],
    *,
    base_dir: str | os.PathLike[str] | None = None,
    max_side: int = 1280,
    synthetic_size: tuple[int, int] = (960, 540),
    side_by_side: bool = False,
) -> dict[str, Any]:
    """H.264 mp4 of the raw skeleton (grey) and the corrected one (colour: left blue, right orange, rotated
    segments red), with a legend. Returns what it measured: the affine camera's residual, px.

    Video and image sources: drawn on their frames (`image_skeletons`: the raw skeleton is the detected 2D
    landmarks, the corrected one those plus the projected 3D correction), scaled so the longer side is at most
    `max_side` px; `side_by_side` puts the raw skeleton on the left copy of the frame and the corrected one on the
    right. Other sources (BVH, JSON without frames): a front view and a top view with the kimono regions K of the
    corrected pose, on a dark background of `synthetic_size`.
    """
    from ._mediapipe import _cv2

    cv2 = _cv2()
    poses = correction.poses
    if poses.raw_positions is None or poses.constraints is None:
        raise ValueError("write_overlay_video needs a corrected sequence")
    frames = _source_frames(poses, Path(base_dir) if base_dir else None)
    if frames is not None:
        source_it, (w0, h0) = frames
        s = min(1.0, max_side / max(w0, h0))
        size = (int(round(w0 * s / 2)) * 2, int(round(h0 * s / 2)) * 2)
        # decoded and scaled ahead in a thread, while this one draws and ffmpeg encodes in its own process
        it = prefetch(None if fr is None else cv2.resize(fr, size) for fr in source_it)
    else:
        it, s = None, 1.0
        size = (synthetic_size[0] // 2 * 2, synthetic_size[1] // 2 * 2)
        scale, pelvis = _views(poses, *size)
    out_size = (2 * size[0], size[1]) if side_by_side and it is not None else size
    fps = float(poses.fps)
    residuals: list[np.ndarray] = []
    with mp4_writer(path, out_size, fps) as send:
        for f in progress(range(poses.n_frames), total=poses.n_frames, desc="video"):
            highlight: set[int] = set()
            for p in range(2):
                if correction.rotated[f, p]:
                    tj = int(correction.target[f, p])
                    highlight |= {tj, *descendants(tj)}
            if it is None:
                img = _synthetic_frame(cv2, poses, f, size, scale, pelvis, correction, highlight)
                _legend(cv2, img, LEGEND, (10, 34))
            else:
                frame = next(it, None)
                img = np.zeros((size[1], size[0], 3), np.uint8) if frame is None else frame
                right = img.copy() if side_by_side else img
                sk = image_skeletons(poses, f, s)
                if sk is not None:
                    raw_uv, cor_uv, res = sk
                    residuals.append(res[np.isfinite(res)])
                    if side_by_side:
                        _draw_skeleton(cv2, img, raw_uv, COLOUR, 3)
                        _draw_skeleton(cv2, right, cor_uv, COLOUR, 3, highlight)
                    else:
                        _draw_skeleton(cv2, img, raw_uv, GREY, 7)
                        _draw_skeleton(cv2, img, cor_uv, COLOUR, 3, highlight)
                if side_by_side:
                    for panel, title in ((img, "raw"), (right, "corrected")):
                        cv2.putText(panel, title, (10, 28), cv2.FONT_HERSHEY_SIMPLEX, 0.8, (255, 255, 255), 2)
                    _legend(cv2, right, LEGEND_SIDE, (10, 40))
                    img = np.hstack([img, right])
                else:
                    _legend(cv2, img, LEGEND)
            label = f"t={poses.times[f]:.2f}s"
            if highlight:
                label += "  corrected: " + ", ".join(
                    JOINTS[t] for t in correction.target[f] if t >= 0 and t in highlight
                )
            cv2.putText(
                img, label, (10, out_size[1] - 12), cv2.FONT_HERSHEY_SIMPLEX, 0.6, (255, 255, 255), 2, cv2.LINE_AA
            )
            send(img[:, :, ::-1])
    if not residuals:
        return {"fit_residual_px": None}
    r = np.concatenate(residuals)
    return {
        "fit_residual_px": {
            "mean": round(float(r.mean()), 2),
            "p95": round(float(np.percentile(r, 95)), 2),
            "worst": round(float(r.max()), 2),
        }
    }


def check_video_output(path: str | os.PathLike[str]) -> None:
    """InputError if an overlay video path cannot be written as mp4 (checked before the work starts)."""
    if Path(path).suffix.lower() != ".mp4":
        raise InputError("the overlay video must be an .mp4 file (H.264)", path)
