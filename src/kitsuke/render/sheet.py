"""Contact sheets: several renders side by side in one image, each with a label underneath."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace
from typing import Any

import numpy as np

from ..errors import InputError
from ..geometry import TriMesh
from .camera import View, frame_camera
from .offscreen import BACKGROUND, DEFAULT_SIZE, ColorLike, Renderer, _check_size, default_renderer, parse_color

SHEET_VIEWS: tuple[View, ...] = ("front", "side", "back")


def contact_sheet(
    images: Sequence[np.ndarray],
    labels: Sequence[str] | None = None,
    *,
    columns: int | None = None,
    background: ColorLike = BACKGROUND[1],
    label_color: ColorLike = (0.22, 0.23, 0.26),
    padding: int = 0,
) -> np.ndarray:
    """Lay images out in a grid with a label strip under each.

    Parameters
    ----------
    images : (H, W, 3|4) uint8 images, all the same H and W; RGBA ones are composited over `background`.
    labels : one text per image (or None for no label strip).
    columns : images per row (default: all in one row).
    background : sRGB colour of the padding and label strips.
    label_color : sRGB colour of the text.
    padding : pixels between and around the panels.

    Returns
    -------
    (rows * (H + label_h + padding) + padding, columns * (W + padding) + padding, 3) uint8 RGB image, where
    label_h = max(18, 4.5% of H) with labels and 0 without.
    """
    from PIL import Image, ImageDraw, ImageFont

    if not images:
        raise InputError("no images for the contact sheet")
    shapes = {np.asarray(im).shape[:2] for im in images}
    if len(shapes) != 1:
        raise InputError(f"contact sheet images differ in size: {sorted(shapes)}")
    if labels is not None and len(labels) != len(images):
        raise InputError(f"{len(labels)} labels for {len(images)} images")
    h, w = shapes.pop()
    n = len(images)
    columns = n if columns is None else max(1, min(int(columns), n))
    rows = -(-n // columns)
    bg = np.array(parse_color(background, what="background"))
    label_h = 0 if labels is None else max(18, round(h * 0.045))
    cell_h = h + label_h
    sheet_w = columns * w + (columns + 1) * padding
    sheet_h = rows * cell_h + (rows + 1) * padding
    sheet = np.empty((sheet_h, sheet_w, 3), dtype=np.uint8)
    sheet[:] = np.rint(bg * 255).astype(np.uint8)
    for i, im in enumerate(images):
        im = np.asarray(im)
        if im.dtype != np.uint8 or im.ndim != 3 or im.shape[2] not in (3, 4):
            raise InputError(f"contact sheet image {i} must be (H, W, 3|4) uint8, got {im.dtype} {im.shape}")
        if im.shape[2] == 4:
            a = im[..., 3:4].astype(np.float32) / 255.0
            im = np.rint(im[..., :3] * a + bg * 255.0 * (1.0 - a)).astype(np.uint8)
        r, c = divmod(i, columns)
        y0, x0 = padding + r * (cell_h + padding), padding + c * (w + padding)
        sheet[y0 : y0 + h, x0 : x0 + w] = im
    if labels is not None:
        pil = Image.fromarray(sheet)
        draw = ImageDraw.Draw(pil)
        font = ImageFont.load_default(size=max(10, round(label_h * 0.62)))
        fill = tuple(round(v * 255) for v in parse_color(label_color, what="label colour"))
        for i, text in enumerate(labels):
            r, c = divmod(i, columns)
            cx = padding + c * (w + padding) + w / 2
            cy = padding + r * (cell_h + padding) + h + label_h / 2
            draw.text((cx, cy), str(text), fill=fill, font=font, anchor="mm")
        sheet = np.asarray(pil)
    return sheet


def render_views(
    meshes: TriMesh | Sequence[TriMesh],
    views: Sequence[View | str] = SHEET_VIEWS,
    *,
    renderer: Renderer | None = None,
    same_scale: bool = True,
    **options: Any,
) -> list[np.ndarray]:
    """Render the same meshes from several named views.

    `same_scale` puts every camera at the same distance (the largest any view needs), so a figure has the same
    size in every image; otherwise each view is framed on its own. Other options as in `Renderer.render`
    (no view/camera).
    """
    if "view" in options or "camera" in options:
        raise InputError("render_views takes `views`, not `view`/`camera`")
    r = renderer or default_renderer()
    if not same_scale or len(views) < 2:
        return [r.render(meshes, view=v, **options) for v in views]
    mesh_list = [meshes] if isinstance(meshes, TriMesh) else list(meshes)
    if not mesh_list:
        raise InputError("no meshes to render")
    points = np.concatenate([m.vertices for m in mesh_list])
    width, height = _check_size(options.get("size", DEFAULT_SIZE), r.max_size, options.get("supersample", 1))
    framing = {k: options[k] for k in ("fov_y_deg", "margin") if k in options}
    cams = [frame_camera(points, v, aspect=width / height, **framing) for v in views]
    dist = max(float(np.linalg.norm(np.subtract(c.eye, c.target))) for c in cams)
    images = []
    for cam in cams:
        back = np.subtract(cam.eye, cam.target)
        eye = np.asarray(cam.target) + back / np.linalg.norm(back) * dist
        images.append(r.render(mesh_list, camera=replace(cam, eye=tuple(eye)), **options))
    return images


def render_sheet(
    meshes: TriMesh | Sequence[TriMesh],
    views: Sequence[View | str] = SHEET_VIEWS,
    *,
    renderer: Renderer | None = None,
    labels: Sequence[str] | None = None,
    same_scale: bool = True,
    **options: Any,
) -> np.ndarray:
    """Render several views of the same meshes into one labelled contact sheet ((H, n*W, 3) uint8 RGB).

    `labels` default to the view names; `same_scale` as in `render_views`; other options as in
    `Renderer.render` (with a None background each panel is composited over the sheet's background).
    """
    images = render_views(meshes, views, renderer=renderer, same_scale=same_scale, **options)
    return contact_sheet(images, list(views) if labels is None else labels)
