"""`kitsuke tryon` on a file or folder: every frame through the mirror, written as an H.264 mp4, with a report.

from kitsuke.tryon import run_tryon
result = run_tryon("clip.mp4", "kimono.mp4", report="r.json", compare=True)
result.summary()["registration"]["mean_px"]

`--compare` writes the uncorrected try-on (the legs poke through the kimono) beside the corrected one.
"""

from __future__ import annotations

import os
import time
from collections import deque
from contextlib import nullcontext
from itertools import islice
from pathlib import Path

import numpy as np

from ..errors import InputError
from .frames import FrameSource, open_frames
from .mirror import MirrorFrame, TryOn, TryOnSettings

#: The registration target (SPEC §5.1, the try-on issue): mean residual at 640x480, pixels.
REGISTRATION_TARGET_PX = 10.0


class TryOnRun:
    """What a try-on run measured.

    source : the source's name, size, fps. keep : how many of the last frames keep their per-frame measures
    (None: all; a live mirror keeps a bounded number, so that a run of hours stays flat in memory). Counts and
    the mean residual cover every frame. frames : `MirrorFrame`s kept (images dropped). latency_s : per kept
    frame, from its arrival to its output, seconds. wall_s : wall time of the run. skipped : frames that did not
    decode. dropped : frames a live run dropped to keep up. ended : why the source ended early, or None.
    """

    def __init__(self, source: dict, keep: int | None = None) -> None:
        self.source = source
        self.frames: deque[MirrorFrame] = deque(maxlen=keep)
        self.latency_s: deque[float] = deque(maxlen=keep)
        self.residuals: deque[np.ndarray] = deque(maxlen=keep)
        self.counts = {"frames": 0, "posed": 0, "several": 0, "corrected": 0, "restarted": 0, "switched": 0}
        self._residual_sum, self._residual_n = 0.0, 0
        self.wall_s = 0.0
        self.skipped = self.dropped = 0
        self.ended: str | None = None

    def add(self, frame: MirrorFrame, arrived: float) -> None:
        """Count a frame that arrived at `arrived` (`time.perf_counter()`) and was output now."""
        self.latency_s.append(time.perf_counter() - arrived)
        c = self.counts
        c["frames"] += 1
        c["posed"] += frame.posed
        c["several"] += frame.people > 1
        c["corrected"] += frame.corrected
        c["restarted"] += frame.restarted
        c["switched"] += frame.switched
        if frame.joint_residuals_px is not None:
            r = frame.joint_residuals_px[np.isfinite(frame.joint_residuals_px)]
            self.residuals.append(r)
            self._residual_sum += float(r.sum())
            self._residual_n += len(r)
        frame.image = frame.raw_image = None  # the video holds them; the report needs the numbers only
        self.frames.append(frame)

    def warnings(self) -> list[str]:
        """What missed its target or went wrong, one line each."""
        out = []
        s = self.summary()
        reg = s["registration"]
        if s["frames_with_pose"] == 0:
            out.append("no person was found in any frame: the video is written without a kimono")
        elif reg["mean_px"] is not None and reg["scaled_mean_px"] > REGISTRATION_TARGET_PX:
            out.append(
                f"registration {reg['scaled_mean_px']:.1f} px mean at 640x480 misses the {REGISTRATION_TARGET_PX:g} px"
                " target"
            )
        if s["frames_without_pose"]:
            out.append(f"{s['frames_without_pose']} frames without a person (the kimono held, then faded)")
        if s["frames_with_several_people"]:
            out.append(
                f"{s['frames_with_several_people']} frames with several people: one was followed (the largest at first)"
            )
        if s["person_switches"]:
            out.append(f"the person followed left {s['person_switches']} times: another was dressed afresh")
        if s["kimono_restarts"]:
            out.append(f"the kimono's simulation failed {s['kimono_restarts']} times and was dressed afresh")
        if self.skipped:
            out.append(f"{self.skipped} frames did not decode and were skipped")
        if self.ended:
            out.append(self.ended)
        return out

    def summary(self) -> dict:
        fr = list(self.frames)
        c = self.counts
        res = np.concatenate(list(self.residuals)) if self.residuals else np.zeros(0)
        mean = self._residual_sum / self._residual_n if self._residual_n else None
        w, h = self.source["size"]
        scale = 640.0 / max(w, h) if max(w, h) > 0 else 1.0  # pixels of the same view at 640x480
        stages = sorted({k for f in fr for k in f.stage_s})
        per_stage = {k: [f.stage_s[k] for f in fr if k in f.stage_s] for k in stages}
        lat = np.array(self.latency_s) if self.latency_s else np.zeros(1)
        strains = [f.strain_max for f in fr if np.isfinite(f.strain_max)]
        return {
            "source": self.source,
            "frames": c["frames"],
            "frames_with_pose": c["posed"],
            "frames_without_pose": c["frames"] - c["posed"],
            "frames_with_several_people": c["several"],
            "frames_corrected": c["corrected"],
            "kimono_restarts": c["restarted"],
            "person_switches": c["switched"],
            "frames_skipped": self.skipped,
            "frames_dropped": self.dropped,
            "ended_early": self.ended,
            "registration": {
                "mean_px": round(mean, 2) if mean is not None else None,
                "p95_px": round(float(np.percentile(res, 95)), 2) if len(res) else None,
                "scaled_mean_px": round(mean * scale, 2) if mean is not None else None,
                "scale_to_640x480": round(scale, 4),
                "target_mean_px": REGISTRATION_TARGET_PX,
            },
            "kimono_strain_max": {
                "median": round(float(np.median(strains)), 4) if strains else None,
                "worst": round(float(np.max(strains)), 4) if strains else None,
            },
            "speed": {
                "fps": round(c["frames"] / self.wall_s, 2) if self.wall_s > 0 else None,
                "latency_ms_median": round(float(np.median(lat)) * 1e3, 1),
                "latency_ms_p95": round(float(np.percentile(lat, 95)) * 1e3, 1),
                "stage_ms_mean": {k: round(float(np.mean(v)) * 1e3, 2) for k, v in per_stage.items()},
            },
            "wall_s": round(self.wall_s, 2),
            "per_frame_kept": len(fr),
            "per_frame": [_frame_row(f) for f in fr],
        }


def _frame_row(f: MirrorFrame) -> dict:
    def r(x: float, d: int = 2) -> float | None:
        return round(float(x), d) if np.isfinite(x) else None

    return {
        "index": f.index,
        "time_s": round(f.time_s, 4),
        "people": f.people,
        "posed": f.posed,
        "corrected": f.corrected,
        "alpha": round(f.alpha, 3),
        "residual_px": r(f.residual_px),
        "residual_p95_px": r(f.residual_p95_px),
        "strain_max": r(f.strain_max, 4),
        "restarted": f.restarted,
        "stage_ms": {k: round(v * 1e3, 2) for k, v in f.stage_s.items()},
    }


def side_by_side(raw: np.ndarray, corrected: np.ndarray) -> np.ndarray:
    """(H, 2W, 3) the uncorrected try-on left, the corrected right, each labelled."""
    import cv2

    out = np.concatenate([raw, corrected], axis=1)
    w = raw.shape[1]
    scale = max(0.4, raw.shape[0] / 900.0)
    for x, text in ((0, "uncorrected pose"), (w, "corrected for the kimono")):
        for color, thick in (((0, 0, 0), 4), ((255, 255, 255), 1)):
            cv2.putText(
                out, text, (x + 10, int(30 * scale)), cv2.FONT_HERSHEY_SIMPLEX, scale, color, thick, cv2.LINE_AA
            )
    return out


def source_info(src: FrameSource) -> dict:
    """The report's record of a source: name, working size, fps, live."""
    return {"name": src.name, "size": list(src.size), "fps": src.fps, "live": src.live}


def run_tryon(
    source: str | os.PathLike[str] | int,
    output: str | os.PathLike[str] | None,
    *,
    report: str | os.PathLike[str] | None = None,
    compare: bool = False,
    plot: str | os.PathLike[str] | None = None,
    settings: TryOnSettings | None = None,
    constraints=None,  # noqa: ANN001 - a ConstraintTable
    fps: float | None = None,
    max_frames: int | None = None,
    garment=None,  # noqa: ANN001 - a kimono dressed on the default body (default: dressed now)
    progress: bool | None = None,
) -> TryOnRun:
    """The try-on over every frame of `source` (a video file, an image folder, or a camera index), written to
    `output` (an H.264 mp4; side by side with the uncorrected try-on when `compare`), with an optional JSON
    `report` and `plot` of the legs (PNG, as `kitsuke pose correct --plot`). fps : an image folder's frame rate.
    max_frames : stop after this many frames.
    InputError for a source that cannot be opened; ComputationError ("simulation") when the kimono diverges:
    then nothing is written."""
    from .._files import write_json_atomic
    from .._progress import progress as bar
    from ..render.video import mp4_writer

    src = open_frames(source, **({"fps": fps} if fps else {}))
    run = TryOnRun(source_info(src))
    width = src.size[0] * (2 if compare else 1)
    t0 = time.perf_counter()
    if max_frames is not None and max_frames < 1:
        raise InputError(f"max_frames must be at least 1, got {max_frames}")
    mirror = TryOn(settings, garment=garment, constraints=constraints, compare=compare, render=output is not None)
    with mirror:
        with nullcontext() if output is None else mp4_writer(output, (width, src.size[1]), src.fps) as send:
            frames = islice(src, max_frames)
            total = src.total if max_frames is None else min(src.total or max_frames, max_frames)
            try:
                for frame in bar(frames, total=total, desc="try-on", enabled=progress or None):
                    out = mirror.step(frame)
                    if send is not None:
                        send(side_by_side(out.raw_image, out.image) if compare else out.image)
                    run.add(out, frame.arrived)
            except KeyboardInterrupt:
                if not src.live:
                    raise
                run.ended = "stopped with Ctrl-C"  # a camera records until stopped: what was recorded is kept
        run.wall_s = time.perf_counter() - t0
    run.skipped, run.ended = src.skipped, run.ended or src.ended
    if report is not None:
        s = run.summary()
        s["warnings"] = run.warnings()
        write_json_atomic(report, s)
    if plot is not None and any(f.posed for f in run.frames):  # else warnings() says nobody was found
        plot_legs(run, plot, constraints)
    return run


def plot_legs(run: TryOnRun, path: str | os.PathLike[str], constraints=None) -> Path:  # noqa: ANN001
    """The knee and ankle distances over the run, raw and corrected, against E(θ) (`kitsuke.pose.plot_distances`).
    The correction is recomputed on the filtered poses: the same result as the live one (tested)."""
    from ..pose import PoseSequence, correct_poses, plot_distances
    from ..skeleton import JOINTS

    if not any(f.posed for f in run.frames):
        raise InputError("no frame had a person in it: nothing to plot", str(path))
    nan = np.full((len(JOINTS), 3), np.nan)
    pos = np.array([f.raw_joints if f.raw_joints is not None else nan for f in run.frames])
    valid = np.array([f.posed for f in run.frames])
    times = np.array([f.time_s for f in run.frames])
    poses = PoseSequence(positions=pos, valid=valid, times=times, fps=float(run.source["fps"]), source=run.source)
    return plot_distances(correct_poses(poses, constraints), path, title=f"try-on legs: {run.source['name']}")
