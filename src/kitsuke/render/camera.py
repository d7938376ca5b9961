"""Cameras: named views of a character, an explicit perspective camera, and auto-framing.

Conventions (SPEC §2): Y up, the character faces +Z, metres. A named view says where the camera stands, seen
from the character:

- ``front``: on +Z looking toward -Z (the character looks at you; its left hand is on the image's right).
- ``back``: on -Z looking toward +Z.
- ``side`` = ``left``: on +X, the character's own left, looking toward -X (the character faces image-left).
- ``right``: on -X, the character's right.
- ``three_quarter``: between front and left (45°), slightly above the chest.

Every named view is auto-framed: the camera looks at the scene from the distance at which all of it fits in
the image with a margin.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal, get_args

import numpy as np

from ..errors import InputError

View = Literal["front", "side", "back", "left", "right", "three_quarter"]
VIEWS: tuple[str, ...] = get_args(View)

#: Unit vector from the scene centre toward the camera, and the camera's elevation above the centre (as a
#: fraction of the distance), per named view.
_VIEW_DIRECTIONS: dict[str, tuple[tuple[float, float, float], float]] = {
    "front": ((0.0, 0.0, 1.0), 0.0),
    "back": ((0.0, 0.0, -1.0), 0.0),
    "side": ((1.0, 0.0, 0.0), 0.0),
    "left": ((1.0, 0.0, 0.0), 0.0),
    "right": ((-1.0, 0.0, 0.0), 0.0),
    "three_quarter": ((np.sqrt(0.5), 0.0, np.sqrt(0.5)), 0.12),
}


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v)


@dataclass(frozen=True)
class Camera:
    """A perspective camera.

    Attributes
    ----------
    eye : (3,) float64, metres, world frame: where the camera is.
    target : (3,) float64, metres, world frame: the point it looks at (the image centre).
    up : (3,) float64: the world direction that shows as up in the image (need not be unit or orthogonal).
    fov_y_deg : vertical field of view, degrees, in (0, 180).
    """

    eye: tuple[float, float, float]
    target: tuple[float, float, float]
    up: tuple[float, float, float] = (0.0, 1.0, 0.0)
    fov_y_deg: float = 30.0

    def __post_init__(self) -> None:
        for name in ("eye", "target", "up"):
            v = np.asarray(getattr(self, name), dtype=np.float64)
            if v.shape != (3,) or not np.all(np.isfinite(v)):
                raise InputError(f"camera {name} must be 3 finite numbers, got {getattr(self, name)!r}")
            object.__setattr__(self, name, tuple(float(x) for x in v))
        if not 0.0 < float(self.fov_y_deg) < 180.0:
            raise InputError(f"camera fov_y_deg must be in (0, 180), got {self.fov_y_deg}")
        forward = np.subtract(self.target, self.eye)
        if np.linalg.norm(forward) < 1e-9:
            raise InputError("camera eye and target coincide")
        if np.linalg.norm(np.cross(_unit(forward), self.up)) < 1e-6:
            raise InputError("camera up is parallel to the viewing direction")

    def basis(self) -> np.ndarray:
        """(3, 3) float64 rows: the camera's right, up and backward unit axes in world coordinates."""
        back = _unit(np.subtract(self.eye, self.target))
        right = _unit(np.cross(self.up, back))
        return np.stack([right, np.cross(back, right), back])

    def view_matrix(self) -> np.ndarray:
        """(4, 4) float64 world -> camera (OpenGL: camera looks down -Z, Y up in the image)."""
        m = np.eye(4)
        m[:3, :3] = self.basis()
        m[:3, 3] = -m[:3, :3] @ np.asarray(self.eye)
        return m

    def projection_matrix(self, aspect: float, near: float, far: float) -> np.ndarray:
        """(4, 4) float64 camera -> clip space; `aspect` = width / height, `near`/`far` in metres (> 0)."""
        f = 1.0 / np.tan(np.radians(self.fov_y_deg) / 2.0)
        m = np.zeros((4, 4))
        m[0, 0] = f / aspect
        m[1, 1] = f
        m[2, 2] = (far + near) / (near - far)
        m[2, 3] = 2.0 * far * near / (near - far)
        m[3, 2] = -1.0
        return m

    def depth_range(self, points: np.ndarray) -> tuple[float, float]:
        """Near and far clip distances (metres) that enclose `points` (n, 3) with room to spare."""
        depth = -(np.asarray(points, dtype=np.float64) @ self.basis()[2] - np.dot(self.basis()[2], self.eye))
        extent = float(np.ptp(points, axis=0).max()) if len(points) else 1.0
        far = max(float(depth.max()), 1e-3) * 1.05 + 0.05 * extent
        # 24-bit depth buffer: keep far/near below ~1e4 for precision; near never behind the eye.
        near = max(float(depth.min()) * 0.95, far * 1e-4, 1e-4)
        return near, far

    def project(self, points: np.ndarray, size: tuple[int, int]) -> np.ndarray:
        """Pixel positions (n, 2) float64 (x right, y down, origin top-left) of world `points` (n, 3)
        in an image of `size` = (width, height) pixels."""
        w, h = size
        p = np.c_[np.asarray(points, dtype=np.float64), np.ones(len(points))]
        clip = p @ (self.projection_matrix(w / h, 0.01, 100.0) @ self.view_matrix()).T
        ndc = clip[:, :2] / clip[:, 3:4]
        return np.c_[(ndc[:, 0] + 1.0) * 0.5 * w, (1.0 - ndc[:, 1]) * 0.5 * h]


def frame_camera(
    points: np.ndarray,
    view: View | str = "front",
    *,
    aspect: float = 0.8,
    fov_y_deg: float = 30.0,
    margin: float = 0.05,
) -> Camera:
    """The camera of a named view that frames `points`.

    Parameters
    ----------
    points : (n, 3) float64, metres, world frame: what must be in the picture (vertices or box corners).
    view : one of VIEWS (see the module docstring for where each stands).
    aspect : image width / height.
    fov_y_deg : vertical field of view, degrees.
    margin : free border on each side, as a fraction of the image width (left/right) and height (top/bottom).

    Returns
    -------
    A Camera at the smallest distance at which every point projects inside the image less the margin, its
    target shifted so that the points' projection is centred.
    """
    if view not in _VIEW_DIRECTIONS:
        raise InputError(f"unknown view {view!r}; choose one of {', '.join(VIEWS)}")
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    if len(pts) == 0 or not np.all(np.isfinite(pts)):
        raise InputError("nothing to frame: no points or non-finite points")
    if not 0.0 <= margin < 0.5:
        raise InputError(f"margin must be in [0, 0.5), got {margin}")
    direction, elevation = _VIEW_DIRECTIONS[view]
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    extent = max(float(np.linalg.norm(hi - lo)), 1e-6)
    back = _unit(np.asarray(direction) + np.array([0.0, elevation, 0.0]))
    up = np.array([0.0, 1.0, 0.0])
    # Half-extent of the usable image at unit distance (the image spans margin .. 1 - margin of each side).
    ty = np.tan(np.radians(fov_y_deg) / 2.0) * (1.0 - 2.0 * margin)
    tx = ty * aspect

    def fit(target: np.ndarray) -> tuple[Camera, float, np.ndarray]:
        cam = Camera(tuple(target + back * extent), tuple(target), tuple(up), fov_y_deg)
        rel = pts - target
        x, y, z = (rel @ cam.basis().T).T
        # A point at depth (dist - z) projects to x / (dist - z); it fits when dist >= z + |x| / tx.
        dist = float(max(np.max(z + np.abs(x) / tx), np.max(z + np.abs(y) / ty), 1e-3))
        sx, sy = x / (dist - z), y / (dist - z)
        shift = np.array([sx.max() + sx.min(), sy.max() + sy.min()]) / 2.0
        return cam, dist, shift

    target = (lo + hi) / 2.0
    # The distance fit is exact for a fixed target; centring the projection moves the target, so iterate.
    for _ in range(6):
        cam, dist, shift = fit(target)
        if abs(shift[0]) < 1e-4 * tx and abs(shift[1]) < 1e-4 * ty:
            break
        right, cup, _ = cam.basis()
        target = target + (right * shift[0] + cup * shift[1]) * dist
    else:
        cam, dist, shift = fit(target)
    return Camera(tuple(target + back * dist), tuple(target), tuple(up), fov_y_deg)
