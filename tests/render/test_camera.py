"""Camera: named views, matrices, projection and auto-framing."""

from __future__ import annotations

import numpy as np
import pytest

from kitsuke.errors import InputError
from kitsuke.render import VIEWS, Camera, frame_camera

from .shapes import box


@pytest.mark.parametrize(
    ("view", "direction"),
    [
        ("front", (0, 0, 1)),
        ("back", (0, 0, -1)),
        ("side", (1, 0, 0)),
        ("left", (1, 0, 0)),
        ("right", (-1, 0, 0)),
        ("three_quarter", (0.7071, 0.0, 0.7071)),
    ],
)
def test_named_views_stand_where_documented(view, direction):
    pts = box().vertices
    cam = frame_camera(pts, view)
    d = np.subtract(cam.eye, cam.target)
    d /= np.linalg.norm(d)
    horizontal = d * [1, 0, 1] / np.linalg.norm(d * [1, 0, 1])
    np.testing.assert_allclose(horizontal, direction, atol=1e-3)
    assert abs(d[1]) < (0.2 if view == "three_quarter" else 1e-9)  # level, three-quarter slightly above
    assert set(VIEWS) == {"front", "back", "side", "left", "right", "three_quarter"}


def test_basis_and_matrices():
    cam = Camera(eye=(0.0, 1.0, 4.0), target=(0.0, 1.0, 0.0), up=(0.0, 1.0, 0.0), fov_y_deg=40.0)
    basis = cam.basis()
    np.testing.assert_allclose(basis @ basis.T, np.eye(3), atol=1e-12)
    np.testing.assert_allclose(basis, [[1, 0, 0], [0, 1, 0], [0, 0, 1]], atol=1e-12)  # front: right = +X
    view = cam.view_matrix()
    np.testing.assert_allclose(view @ [0.0, 1.0, 0.0, 1.0], [0, 0, -4, 1], atol=1e-12)  # target: 4 m ahead
    proj = cam.projection_matrix(1.5, 1.0, 10.0)
    for z, ndc_z in ((-1.0, -1.0), (-10.0, 1.0)):  # near and far planes map to -1 and +1
        clip = proj @ [0.0, 0.0, z, 1.0]
        assert clip[2] / clip[3] == pytest.approx(ndc_z)
    # A point at the top edge of the field of view projects to the image's top row.
    top = [0.0, 1.0 + 4.0 * np.tan(np.radians(20.0)), 0.0]
    px = cam.project(np.array([top, [0.0, 1.0, 0.0]]), (300, 200))
    np.testing.assert_allclose(px, [[150, 0], [150, 100]], atol=1e-9)


def test_frame_camera_fits_all_points_tightly_and_centred():
    rng = np.random.default_rng(3)
    pts = rng.normal(size=(500, 3)) * [0.3, 0.8, 0.15] + [1.0, 2.0, -3.0]
    size = (400, 500)
    for view in VIEWS:
        for margin in (0.0, 0.05, 0.2):
            cam = frame_camera(pts, view, aspect=size[0] / size[1], margin=margin)
            px = cam.project(pts, size)
            lo, hi = px.min(axis=0), px.max(axis=0)
            m = margin * np.array(size)
            assert np.all(lo >= m - 1e-6) and np.all(hi <= np.array(size) - m + 1e-6)
            # Tight: the limiting axis reaches the margin; centred on both axes (within a tenth of a pixel).
            assert np.min(np.r_[lo - m, np.array(size) - m - hi]) < 0.1
            np.testing.assert_allclose((lo + hi) / 2, np.array(size) / 2, atol=0.1)


def test_depth_range_encloses_the_scene():
    pts = box().vertices
    cam = frame_camera(pts, "front")
    near, far = cam.depth_range(pts)
    depth = -(pts - cam.eye) @ cam.basis()[2]
    assert 0 < near < depth.min() and far > depth.max()


def test_frame_camera_bad_input():
    with pytest.raises(InputError, match="unknown view"):
        frame_camera(box().vertices, "top")
    with pytest.raises(InputError, match="nothing to frame"):
        frame_camera(np.zeros((0, 3)))
    with pytest.raises(InputError, match="nothing to frame"):
        frame_camera(np.full((3, 3), np.nan))
    with pytest.raises(InputError, match="margin"):
        frame_camera(box().vertices, margin=0.5)
