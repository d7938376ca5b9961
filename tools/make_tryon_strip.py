"""Rebuild docs/tryon_strip.png, the README's picture of the try-on: two frames of the squats clip, then one frame
of the balancing clip without and with the posture correction (the frame where the correction turns a leg most).

Run from the repository root: `python tools/make_tryon_strip.py [-o docs/tryon_strip.png]` (about a minute).
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
SQUATS = ROOT / "tests" / "data" / "pose" / "tfjs_pose_squats.mp4"
BALANCING = ROOT / "tests" / "data" / "pose" / "pose2sim_balancing_cam01.mp4"
HEIGHT = 480


def frames_of(path: Path, compare: bool) -> list:
    from kitsuke.tryon import TryOn, open_frames

    out = []
    with TryOn(compare=compare) as mirror:
        for frame in open_frames(path):
            out.append(mirror.step(frame))
    return out


def label(rgb: np.ndarray, text: str) -> np.ndarray:
    import cv2

    img = np.ascontiguousarray(rgb)
    for color, thick in (((0, 0, 0), 4), ((255, 255, 255), 1)):
        cv2.putText(img, text, (8, 24), cv2.FONT_HERSHEY_SIMPLEX, 0.6, color, thick, cv2.LINE_AA)
    return img


def main() -> None:
    import cv2
    from PIL import Image

    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("-o", "--output", type=Path, default=ROOT / "docs" / "tryon_strip.png")
    args = ap.parse_args()
    squats = frames_of(SQUATS, compare=False)
    heights = [f.joints[:, 1].max() - f.joints[:, 1].min() if f.joints is not None else 0 for f in squats]
    stand, squat = int(np.argmax(heights[5:])) + 5, int(np.argmin(heights[5:])) + 5
    balancing = frames_of(BALANCING, compare=True)
    moved = [np.abs(f.joints - f.raw_joints).max() if f.posed else 0.0 for f in balancing]
    k = int(np.argmax(moved))
    tiles = [
        label(squats[stand].image, "squats: standing"),
        label(squats[squat].image, "squats: down"),
        label(balancing[k].raw_image, "leg raised: raw pose"),
        label(balancing[k].image, "corrected for the kimono"),
    ]
    tiles = [
        cv2.resize(t, (int(t.shape[1] * HEIGHT / t.shape[0]), HEIGHT), interpolation=cv2.INTER_AREA) for t in tiles
    ]
    args.output.parent.mkdir(parents=True, exist_ok=True)
    Image.fromarray(np.concatenate(tiles, axis=1)).save(args.output, optimize=True)
    print(
        f"wrote {args.output} (squats frames {stand}, {squat}; balancing frame {k}, leg moved {100 * moved[k]:.0f} cm)"
    )


if __name__ == "__main__":
    main()
