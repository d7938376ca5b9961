"""Registration: the perspective camera that shows the posed body where the person stands in the image.

The camera is a pinhole with square pixels and its principal point at the image centre. Its focal length is
fitted once, over the first frames (`fit_focal`: the field of view that projects the posed joints closest to
the detected ones); its pose is fitted every frame (`register`: OpenCV's iterative PnP, started from the previous
frame's pose or, on the first, from MediaPipe's own axes, which are the camera's). The body keeps its own size:
a perspective camera cannot tell a larger body farther away from a smaller one nearer, so fitting the camera's
distance is what scales the body to the person's height in the image.

Conventions: camera coordinates as OpenCV's (x right, y down, z forward, metres); pixels with the origin at the
top-left corner of the image.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..render.camera import Camera

#: A joint takes part in the fit when MediaPipe sees it at least this well (visibility in [0, 1]).
MIN_VISIBILITY = 0.5
#: Fewer visible joints than this and the frame is not registered (PnP needs 4; a few more make it stable).
MIN_JOINTS = 6
#: MediaPipe's world axes (x right, y down, z away from the camera) in kitsuke's (Y up, the body facing +Z):
#: kitsuke -> camera is this rotation before any fit.
KITSUKE_TO_CAMERA = np.diag([1.0, -1.0, -1.0])
#: The field of view searched by `fit_focal`, degrees along the image's longer side (phones and webcams: 50-80°).
FOV_RANGE_DEG = (25.0, 100.0)


def focal_px(size: tuple[int, int], fov_deg: float) -> float:
    """Focal length in pixels of a camera whose field of view along the image's longer side is `fov_deg`."""
    return 0.5 * max(size) / math.tan(math.radians(fov_deg) / 2.0)


@dataclass(frozen=True)
class Registration:
    """The camera of one frame.

    focal_px : focal length, pixels. size : (width, height) of the image, pixels.
    rotation : (3, 3) kitsuke world -> camera. translation : (3,) metres (camera = rotation @ world + translation).
    residual_px : (J,) distance between each projected posed joint and the detected one, pixels; NaN for joints
        not used (seen too poorly).
    """

    focal_px: float
    size: tuple[int, int]
    rotation: np.ndarray
    translation: np.ndarray

    residual_px: np.ndarray

    @property
    def intrinsics(self) -> np.ndarray:
        """(3, 3) the camera matrix K."""
        w, h = self.size
        return np.array([[self.focal_px, 0.0, w / 2.0], [0.0, self.focal_px, h / 2.0], [0.0, 0.0, 1.0]])

    @property
    def mean_residual_px(self) -> float:
        return float(np.nanmean(self.residual_px))

    def project(self, points: np.ndarray) -> np.ndarray:
        """(n, 2) pixels of world points (n, 3), metres."""
        cam = np.asarray(points, dtype=np.float64) @ self.rotation.T + self.translation
        uv = cam @ self.intrinsics.T
        return uv[:, :2] / uv[:, 2:3]

    def camera(self) -> Camera:
        """The same camera as a `kitsuke.render.Camera`, to render the body and kimono over the frame."""
        r = self.rotation
        eye = -r.T @ self.translation
        forward = r.T @ np.array([0.0, 0.0, 1.0])
        up = r.T @ np.array([0.0, -1.0, 0.0])
        fov_y = 2.0 * math.degrees(math.atan(self.size[1] / 2.0 / self.focal_px))
        return Camera(tuple(eye), tuple(eye + forward), tuple(up), fov_y)


def _used(image: np.ndarray) -> np.ndarray:
    return np.isfinite(image).all(axis=1) & (image[:, 2] >= MIN_VISIBILITY)


def _translation_for(rotation: np.ndarray, points: np.ndarray, uv: np.ndarray, f: float, c: np.ndarray) -> np.ndarray:
    """The translation that best projects `points` (n, 3) onto `uv` (n, 2) for a fixed rotation: linear least
    squares in the image plane scaled by depth ((u - c) z = f x for each axis)."""
    p = points @ rotation.T
    d = uv - c
    a = np.zeros((2 * len(p), 3))
    a[0::2, 0] = f
    a[0::2, 2] = -d[:, 0]
    a[1::2, 1] = f
    a[1::2, 2] = -d[:, 1]
    b = np.empty(2 * len(p))
    b[0::2] = d[:, 0] * p[:, 2] - f * p[:, 0]
    b[1::2] = d[:, 1] * p[:, 2] - f * p[:, 1]
    return np.linalg.lstsq(a, b, rcond=None)[0]


def register(
    joints: np.ndarray,
    image: np.ndarray,
    focal: float,
    size: tuple[int, int],
    previous: Registration | None = None,
) -> Registration | None:
    """Fit the camera that projects the posed body's `joints` (J, 3) metres onto the detected `image` joints
    (J, 3: u, v pixels and visibility), for a focal length `focal` pixels and an image of `size` (w, h).

    Starts from `previous` (the last frame's camera) when given. None when too few joints are seen
    (`MIN_JOINTS`) or the fit fails (the person behind the camera, non-finite values).
    """
    import cv2

    used = _used(image)
    if used.sum() < MIN_JOINTS or not np.isfinite(joints[used]).all():
        return None
    obj = np.ascontiguousarray(joints[used], dtype=np.float64)
    uv = np.ascontiguousarray(image[used, :2], dtype=np.float64)
    c = np.array([size[0] / 2.0, size[1] / 2.0])
    k = np.array([[focal, 0.0, c[0]], [0.0, focal, c[1]], [0.0, 0.0, 1.0]])
    if previous is not None:
        rotation, translation = previous.rotation, previous.translation
    else:
        rotation = KITSUKE_TO_CAMERA
        translation = _translation_for(rotation, obj, uv, focal, c)
    rvec, _ = cv2.Rodrigues(rotation)
    ok, rvec, tvec = cv2.solvePnP(
        obj, uv, k, None, rvec, translation.reshape(3, 1).copy(), useExtrinsicGuess=True, flags=cv2.SOLVEPNP_ITERATIVE
    )
    if not ok or not (np.isfinite(rvec).all() and np.isfinite(tvec).all()):
        return None
    rotation = cv2.Rodrigues(rvec)[0]
    translation = tvec.ravel()
    if ((obj @ rotation.T + translation)[:, 2] <= 0).any():
        return None  # the fit put the person behind the camera
    out = Registration(float(focal), (int(size[0]), int(size[1])), rotation, translation, np.full(len(joints), np.nan))
    out.residual_px[used] = np.linalg.norm(out.project(obj) - uv, axis=1)
    return out


def fit_focal(frames: list[tuple[np.ndarray, np.ndarray]], size: tuple[int, int]) -> float:
    """The focal length (pixels) that registers the given frames best: golden-section search over the field of
    view (`FOV_RANGE_DEG`) for the smallest mean residual. frames : (posed joints (J, 3), image joints (J, 3))
    pairs, a few seconds' worth. With no usable frame, a 60° field of view."""

    def cost(fov: float) -> float:
        res = [register(x, img, focal_px(size, fov), size) for x, img in frames]
        got = [r.mean_residual_px for r in res if r is not None]
        return float(np.mean(got)) if got else math.inf

    lo, hi = FOV_RANGE_DEG
    g = (math.sqrt(5.0) - 1.0) / 2.0
    a, b = hi - g * (hi - lo), lo + g * (hi - lo)
    fa, fb = cost(a), cost(b)
    if not (math.isfinite(fa) or math.isfinite(fb)):
        return focal_px(size, 60.0)
    while hi - lo > 1.0:  # to a degree: the residual is flat within a few degrees of its minimum
        if fa <= fb:
            hi, b, fb = b, a, fa
            a = hi - g * (hi - lo)
            fa = cost(a)
        else:
            lo, a, fa = a, b, fb
            b = lo + g * (hi - lo)
            fb = cost(b)
    return focal_px(size, 0.5 * (lo + hi))
