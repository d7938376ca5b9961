"""Poses and kimono posture correction (SPEC §2, §3.4, §5.2, §5.3).

Sources (all give a `PoseSequence` in the SPEC §2 joint set, metres, Y up, facing +Z):
- `load_poses(source)`: video file, image, folder of images, camera index, BVH or kitsuke poses JSON;
- `extract_video`, `extract_images`, `extract_camera`: MediaPipe PoseLandmarker with the packaged model;
- `load_bvh`: BVH motion capture, joint names mapped by rules (CMU, MakeHuman, DAZ, Mixamo, ...);
- `read_poses` / `write_poses`: the `kitsuke.poses` v1 JSON file.
Filtering: `filter_poses` (One-Euro, `OneEuroConfig`).
Correction: `correct_poses(poses, constraints)` → `Correction`; `correction_measures`, `check_invariants`.
Constraints: `ConstraintTable`, `PairLimit`, `read_constraints`, `write_constraints`, `default_constraints` (the
shipped table calibrated by simulation), `packaged_constraints` / `load_constraints` (shipped tables by name:
"calibrated", "geometric"), `geometric_estimate`, `write_default_constraints` (the geometric table's file).
Outputs: `plot_distances` (PNG), `write_overlay_video` (H.264 mp4).

mediapipe, OpenCV and matplotlib are imported only by the functions that need them.
"""

from ._bvh import BvhFile, forward_kinematics, read_bvh
from ._bvh_map import load_bvh, map_bvh_joints, parse_joint_name
from ._constraints import (
    ConstraintTable,
    KimonoLegGeometry,
    PairLimit,
    default_constraints,
    geometric_estimate,
    load_constraints,
    packaged_constraints,
    read_constraints,
    write_constraints,
    write_default_constraints,
)
from ._correct import Correction, OnlineCorrector, check_invariants, correct_poses, correction_measures
from ._filter import OneEuroConfig, OneEuroFilter, filter_poses, one_euro
from ._landmarks import LANDMARKS, image_to_joints, world_to_joints
from ._mediapipe import PoseLandmarker, extract_camera, extract_images, extract_video
from ._output import fit_affine_camera, plot_distances, write_overlay_video
from ._sequence import PoseSequence, poses_from_json, poses_to_json, read_poses, write_poses
from ._sources import load_poses, source_kind

__all__ = [
    "LANDMARKS",
    "BvhFile",
    "ConstraintTable",
    "Correction",
    "KimonoLegGeometry",
    "OneEuroConfig",
    "OneEuroFilter",
    "OnlineCorrector",
    "PairLimit",
    "PoseLandmarker",
    "PoseSequence",
    "check_invariants",
    "correct_poses",
    "correction_measures",
    "default_constraints",
    "load_constraints",
    "packaged_constraints",
    "extract_camera",
    "extract_images",
    "extract_video",
    "filter_poses",
    "fit_affine_camera",
    "forward_kinematics",
    "geometric_estimate",
    "image_to_joints",
    "load_bvh",
    "load_poses",
    "map_bvh_joints",
    "one_euro",
    "parse_joint_name",
    "plot_distances",
    "poses_from_json",
    "poses_to_json",
    "read_bvh",
    "read_constraints",
    "read_poses",
    "source_kind",
    "world_to_joints",
    "write_constraints",
    "write_default_constraints",
    "write_overlay_video",
    "write_poses",
]
