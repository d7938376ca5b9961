"""Arm axes found from a body's mesh alone (kitsuke.body.arms): along the upper arm, outwards and down, one per side."""

import numpy as np
import pytest

from kitsuke.body import default_body, load_body
from kitsuke.body.arms import arm_axes
from kitsuke.geometry import TriMesh

from ..conftest import DATA


@pytest.fixture(scope="module")
def bodies():
    return {"default": default_body(), "mean_all": load_body(DATA / "bodies" / "mean_all.obj")}


def _angle_deg(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.degrees(np.arccos(np.clip(a @ b / np.linalg.norm(a) / np.linalg.norm(b), -1.0, 1.0))))


def test_the_default_bodys_arm_axes_follow_its_upper_arm_bones(bodies):
    body = bodies["default"]
    axes = arm_axes(body.mesh)
    assert set(axes) == {"left", "right"}
    for side, p in (("left", "l_"), ("right", "r_")):
        shoulder, elbow = body.rig.joint(p + "shoulder"), body.rig.joint(p + "elbow")
        axis = axes[side]
        assert _angle_deg(elbow - shoulder, axis.direction) < 15.0, side
        assert axis.distance(elbow[None])[0] < 0.03, side  # the axis runs through the arm, not beside it
        assert 0.02 < axis.radius_m < 0.06, side
        assert np.sign(axis.direction[0]) == (1 if side == "left" else -1) and axis.direction[1] < 0, side


def test_arm_axes_of_a_scan_in_another_a_pose_are_mirror_images(bodies):
    axes = arm_axes(bodies["mean_all"].mesh)
    left, right = axes["left"], axes["right"]
    mirror = np.array([-1.0, 1.0, 1.0])
    assert _angle_deg(left.direction, right.direction * mirror) < 3.0
    np.testing.assert_allclose(left.start, right.start * mirror, atol=0.01)
    # GarmentCode's mean_all holds its arms about 40 degrees below the horizontal.
    assert 30.0 < np.degrees(np.arcsin(-left.direction[1])) < 50.0
    assert left.length_m > 0.15


def test_a_body_without_arms_apart_has_no_arm_axes():
    # A box (a torso with its arms at its sides, as far as the cut can tell): one part at every height.
    corners = np.array([[x, y, z] for x in (-0.2, 0.2) for y in (0.0, 1.7) for z in (-0.1, 0.1)])
    faces = np.array(
        [[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1], [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4],
         [1, 5, 7], [1, 7, 3]]
    )  # fmt: skip
    assert arm_axes(TriMesh(corners, faces)) == {}
