"""Places on the body named for messages (kitsuke.body.regions): the armpits, shoulders and arms from the arms found
in the mesh, the torso's parts by height and side, the legs'."""

import numpy as np
import pytest

from kitsuke.body import default_body, load_body
from kitsuke.body.regions import BodyRegions
from kitsuke.errors import InputError

from ..conftest import DATA


@pytest.fixture(scope="module", params=["default", "mean_all"])
def body(request):
    return default_body() if request.param == "default" else load_body(DATA / "bodies" / "mean_all.obj")


def test_places_on_a_rigged_body_are_named_after_its_joints():
    body = default_body()
    regions = BodyRegions.of(body.mesh)
    j = body.rig.joint
    # Just below the shoulder joint, inside the armpit; just above it, on the shoulder.
    for side, p in (("left", "l_"), ("right", "r_")):
        shoulder, elbow, wrist = j(p + "shoulder"), j(p + "elbow"), j(p + "wrist")
        armpit = regions.arms[side].start + np.array([0.0, -0.02, 0.0])
        assert regions.name(armpit) == f"under the {side} arm"
        assert regions.name(shoulder + np.array([0.0, 0.06, 0.0])) in (f"at the {side} shoulder", "at the "
                                                                       f"{side} side of the shoulders")  # fmt: skip
        assert regions.name(0.3 * shoulder + 0.7 * elbow) == f"on the {side} upper arm"
        assert regions.name(0.5 * elbow + 0.5 * wrist) == f"on the {side} forearm"
        knee = j(p + "knee")
        assert regions.name(knee) == f"at the {side} knee"
        assert regions.name(0.5 * j(p + "hip") + 0.5 * knee) == f"on the {side} thigh"
        assert regions.name(j(p + "ankle")) == f"at the {side} ankle"
    neck = 0.5 * (j("neck") + j("head"))
    assert regions.name(neck + np.array([0.0, 0.0, -0.06])) == "at the back of the neck"
    assert regions.name(neck + np.array([0.0, 0.0, 0.06])) == "at the front of the neck"


def test_the_torso_is_named_by_height_and_side(body):
    regions = BodyRegions.of(body.mesh)
    cx, cz = regions.centre
    y = regions.floor_y + 0.6 * regions.height_m  # the waist
    assert regions.name(np.array([cx, y, cz + 0.2])) == "at the front of the waist"
    assert regions.name(np.array([cx, y, cz - 0.2])) == "at the back of the waist"
    assert regions.name(np.array([cx + 0.2, y, cz])) == "at the left side of the waist"
    assert regions.name(np.array([cx - 0.2, y, cz + 0.05])) == "at the right side of the waist"
    chest = regions.floor_y + 0.72 * regions.height_m
    assert regions.name(np.array([cx, chest, cz + 0.2])) == "at the front of the chest"
    hips = regions.crotch_y + 0.05
    assert regions.name(np.array([cx, hips, cz - 0.2])) == "at the back of the hips"


def test_a_body_without_arms_found_names_the_heights_alone():
    body = default_body()
    regions = BodyRegions.of(body.mesh)
    armless = BodyRegions(regions.floor_y, regions.height_m, regions.centre, regions.crotch_y, {})
    armpit = regions.arms["left"].start + np.array([0.0, -0.02, 0.0])
    assert armless.name(armpit) == "at the left side of the chest"


def test_points_off_the_body_are_named_after_the_nearest_part_and_bad_points_refused():
    body = default_body()
    regions = BodyRegions.of(body.mesh)
    cx, cz = regions.centre
    below = np.array([cx + 0.1, regions.floor_y - 0.05, cz])  # a train pooled under the floor's height
    assert regions.name(below) == "at the left ankle"
    above = np.array([cx, regions.floor_y + regions.height_m + 0.2, cz - 0.2])
    assert regions.name(above) == "at the back of the neck"
    for bad in ([np.nan, 1.0, 0.0], [0.0, 1.0]):
        with pytest.raises(InputError, match="3 finite numbers"):
            regions.name(np.array(bad))
