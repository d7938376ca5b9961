"""Renderer: coverage, framing, orientation, lighting, textures, double-sided cloth, transparency, bad input."""

from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

from kitsuke.errors import InputError
from kitsuke.geometry import TriMesh
from kitsuke.render import Camera, Renderer, read_texture, render, write_png

from .shapes import BG, box, checker, luminance, mask_bbox, quad, sphere, subject_mask

SIZE = (200, 250)


def test_box_covers_twice_the_area_from_the_front_as_from_the_side(renderer):
    # 0.4 wide x 1.7 tall x 0.2 deep: the height sets the scale in both views, so the width ratio is ~2.
    b = box()
    front = subject_mask(renderer.render(b, view="front", size=SIZE, background=BG, shading="flat"))
    side = subject_mask(renderer.render(b, view="side", size=SIZE, background=BG, shading="flat"))
    # Expected front coverage: 90% of the height, 0.4/1.7 of that in width -> ~0.9 * 0.235 * 250/200 ~ 0.24.
    assert 0.20 < front.mean() < 0.29
    assert 0.10 < side.mean() < 0.15
    assert 1.7 < front.mean() / side.mean() < 2.3
    fx0, _, fx1, _ = mask_bbox(front)
    sx0, _, sx1, _ = mask_bbox(side)
    assert 1.7 < (fx1 - fx0 + 1) / (sx1 - sx0 + 1) < 2.3


@pytest.mark.parametrize("view", ["front", "side", "back", "three_quarter"])
def test_subject_is_framed_with_a_margin(renderer, view):
    w, h = SIZE
    for mesh in (box(), sphere(0.5, center=(3.0, -2.0, 1.0))):  # also far from the origin
        mask = subject_mask(renderer.render(mesh, view=view, size=SIZE, background=None))
        x0, y0, x1, y1 = mask_bbox(mask)
        # Default margin = 5% of the image on each side; the limiting axis touches it (within 2 px).
        assert x0 >= 0.05 * w - 2 and x1 <= 0.95 * w + 1 and y0 >= 0.05 * h - 2 and y1 <= 0.95 * h + 1
        assert min(x0, y0 * w / h, w - 1 - x1, (h - 1 - y1) * w / h) <= 0.05 * w + 2
        # Centred: equal free space left/right and top/bottom (within 2 px).
        assert abs(x0 - (w - 1 - x1)) <= 2 and abs(y0 - (h - 1 - y1)) <= 2


def test_views_follow_the_conventions(renderer):
    """Y up, facing +Z: front sees from +Z (character's left = +X on image right), side from +X, back from -Z."""
    torso = box(0.6, 1.0, 0.3)
    left_hand = sphere(0.12, center=(0.45, 0.5, 0.0), name="left")  # the character's left is +X
    nose = sphere(0.08, center=(0.0, 0.8, 0.2), name="nose")  # in front of the torso (+Z)
    colors = ["white", "red", "blue"]

    def where(view, channel):
        img = renderer.render([torso, left_hand, nose], view=view, size=SIZE, colors=colors, background="black")
        other = [c for c in range(3) if c != channel]
        hit = (img[..., channel].astype(int) - img[..., other].max(axis=2)) > 60
        return hit, (np.nonzero(hit)[1].mean() / SIZE[0] if hit.any() else None)

    front_left, x_front = where("front", 0)
    back_left, x_back = where("back", 0)
    assert x_front > 0.7 and x_back < 0.3
    nose_front, _ = where("front", 2)
    nose_back, _ = where("back", 2)
    assert nose_front.sum() > 50 and nose_back.sum() == 0  # the nose is in front: hidden from behind
    # From the character's left (+X) the left hand faces the camera, in front of the torso, near the middle.
    side_left, x_side = where("side", 0)
    assert side_left.sum() > front_left.sum() and 0.35 < x_side < 0.65
    _, x_nose_side = where("side", 2)
    assert x_nose_side < 0.45  # the character faces image-left in the side view
    right_left, _ = where("right", 0)
    assert right_left.sum() == 0  # the left hand is behind the torso seen from the right


def test_lighting_shades_a_sphere(renderer):
    img = renderer.render(sphere(), size=SIZE, background=BG)
    mask = subject_mask(img)
    lum = luminance(img)
    inside = lum[mask]
    assert inside.std() > 15 and np.percentile(inside, 98) - np.percentile(inside, 2) > 80
    # Key light from the camera's upper left: that quadrant is brighter than the lower right one.
    h, w = mask.shape
    ul = lum[: h // 2, : w // 2][mask[: h // 2, : w // 2]].mean()
    lr = lum[h // 2 :, w // 2 :][mask[h // 2 :, w // 2 :]].mean()
    assert ul > lr + 20


def test_flat_shading_gives_a_box_uniform_faces(renderer):
    # Three faces of a box seen from the three-quarter view: flat shading gives few distinct levels per face.
    img = renderer.render(box(1.0, 1.0, 1.0), view="three_quarter", size=SIZE, background=BG, shading="flat")
    lum = luminance(img)[subject_mask(img)]
    levels = np.unique(np.rint(lum / 8))
    assert len(levels) >= 2
    smooth = renderer.render(box(1.0, 1.0, 1.0), view="three_quarter", size=SIZE, background=BG)
    assert not np.array_equal(img, smooth)


def test_checker_texture_shows_both_colours(renderer):
    plane = quad(1.0, uv_repeat=2.0)
    plane.texture = checker()
    img = renderer.render(plane, view="front", size=SIZE, background=(0.5, 0.5, 0.5)).astype(int)
    red = (img[..., 0] - img[..., 2]) > 80
    blue = (img[..., 2] - img[..., 0]) > 80
    area = SIZE[0] * SIZE[1]
    assert red.sum() > 0.15 * area and blue.sum() > 0.15 * area
    # A UV repeat of 2 over an 8x8 checker: 16 cells across; count colour changes along the middle row.
    row = red[SIZE[1] // 2]
    assert 12 <= np.count_nonzero(np.diff(row.astype(int))) <= 17


def test_texture_rows_map_v_up(renderer):
    # Top half of the image red, bottom half blue: uv v = 1 is the top of the texture (OBJ/glTF-from-OBJ rule).
    tex = np.zeros((64, 64, 3), np.uint8)
    tex[:32] = (230, 20, 20)
    tex[32:] = (20, 20, 230)
    plane = quad(1.0)
    plane.texture = tex
    img = renderer.render(plane, size=SIZE, background="black").astype(int)
    top, bottom = img[SIZE[1] // 2 - 30], img[SIZE[1] // 2 + 30]
    assert top[100, 0] > top[100, 2] + 80 and bottom[100, 2] > bottom[100, 0] + 80


def test_single_sided_cloth_is_visible_and_shaded_from_behind(renderer):
    cloth = quad(1.0)  # faces +Z
    front = renderer.render(cloth, view="front", size=SIZE, background=None)
    back = renderer.render(cloth, view="back", size=SIZE, background=None)
    fm, bm = subject_mask(front), subject_mask(back)
    assert bm.mean() > 0.5 and abs(fm.mean() - bm.mean()) < 0.01
    lum_front, lum_back = luminance(front)[fm].mean(), luminance(back)[bm].mean()
    # The back is lit with the flipped normal (not black), a little darker to read as the inside.
    assert 0.55 * lum_front < lum_back < 0.95 * lum_front


def test_transparent_background(renderer):
    img = renderer.render(sphere(), size=SIZE, background=None)
    assert img.shape == (SIZE[1], SIZE[0], 4) and img.dtype == np.uint8
    alpha = img[..., 3]
    yy, xx = np.mgrid[: SIZE[1], : SIZE[0]]
    # The sphere's disc: centre (99.5, 124.5) px, radius ~90 px (framed with a 5% margin of the 200 px width).
    r = np.hypot(xx - 99.5, yy - 124.5)
    assert np.all(alpha[r > 95] == 0)
    assert np.all(alpha[r < 85] == 255)
    # Anti-aliased silhouette: partial coverage on the rim, and straight (not premultiplied) colour there.
    rim = (alpha > 0) & (alpha < 255)
    assert rim.sum() > 100
    assert luminance(img)[rim].mean() > 0.6 * luminance(img)[alpha == 255].mean()


def test_background_colour_and_gradient(renderer):
    img = renderer.render(sphere(), size=SIZE, background="#336699")
    assert img.shape == (SIZE[1], SIZE[0], 3)
    assert tuple(img[0, 0]) == (0x33, 0x66, 0x99) and tuple(img[-1, -1]) == (0x33, 0x66, 0x99)
    grad = renderer.render(sphere(), size=SIZE, background=("white", "black"))
    assert grad[0, 0, 0] > 250 and grad[-1, 0, 0] < 5 and 100 < grad[SIZE[1] // 2, 0, 0] < 155


def test_wireframe_draws_dark_edges(renderer):
    s = sphere(subdivisions=2)
    plain = luminance(renderer.render(s, size=SIZE, background=BG))
    wire = luminance(renderer.render(s, size=SIZE, background=BG, wireframe=True))
    darker = (plain - wire) > 25
    assert 0.03 < darker.mean() < 0.4


def test_colours_default_and_given(renderer):
    body, cloth = sphere(0.5, name="body"), sphere(0.3, center=(0.0, 0.0, 0.45), name="cloth")
    default = renderer.render([body, cloth], size=SIZE, background="black").astype(int)
    centre, edge = default[125, 100], default[125, 20]
    assert centre[2] > centre[0]  # cloth default: blue
    assert edge[0] > edge[2]  # body default: skin tone
    red = renderer.render([body], size=SIZE, colors=["red"], background="black").astype(int)
    assert red[125, 100, 0] > 3 * max(red[125, 100, 1], red[125, 100, 2])


def test_supersampling_and_msaa_agree(renderer):
    a = renderer.render(sphere(), size=SIZE, background=None)
    b = renderer.render(sphere(), size=SIZE, background=None, supersample=2, samples=1)
    assert b.shape == a.shape
    assert abs(subject_mask(a).mean() - subject_mask(b).mean()) < 0.01
    assert len(np.unique(b[..., 3])) > 3  # the averaged edge is anti-aliased too


def test_explicit_camera(renderer):
    s = sphere(0.5)
    near = Camera(eye=(0.0, 0.0, 3.0), target=(0.0, 0.0, 0.0), fov_y_deg=30.0)
    far = Camera(eye=(0.0, 0.0, 6.0), target=(0.0, 0.0, 0.0), fov_y_deg=30.0)
    c_near = subject_mask(renderer.render(s, camera=near, size=SIZE, background=None)).mean()
    c_far = subject_mask(renderer.render(s, camera=far, size=SIZE, background=None)).mean()
    assert 3.3 < c_near / c_far < 4.7  # apparent area ~ 1 / distance^2
    # Off-centre target: the sphere moves to the image's left when the camera looks to its right.
    right = Camera(eye=(0.5, 0.0, 4.0), target=(0.5, 0.0, 0.0))
    x0, _, x1, _ = mask_bbox(subject_mask(renderer.render(s, camera=right, size=SIZE, background=None)))
    assert (x0 + x1) / 2 < 0.4 * SIZE[0]


def test_module_level_render_reuses_one_context():
    from kitsuke.render import default_renderer

    img = render(box(), view="side", size=(64, 80), background=None)
    assert img.shape == (80, 64, 4) and subject_mask(img).any()
    assert default_renderer() is default_renderer()


def test_renderer_reports_its_driver(renderer):
    assert isinstance(renderer.renderer_name, str) and renderer.renderer_name
    assert renderer.max_samples >= 1


# -- bad input ----------------------------------------------------------------------------------------------


def test_bad_meshes_raise_input_error(renderer):
    with pytest.raises(InputError, match="empty"):
        renderer.render(TriMesh(np.zeros((0, 3)), np.zeros((0, 3)), name="nothing"))
    nan = box()
    nan.vertices[3, 1] = np.nan
    with pytest.raises(InputError, match="NaN"):
        renderer.render(nan)
    bad_faces = box()
    bad_faces.faces[0, 0] = 99
    with pytest.raises(InputError, match="face indices"):
        renderer.render(bad_faces)
    no_uv = box()
    no_uv.texture = checker()
    with pytest.raises(InputError, match="no uv"):
        renderer.render(no_uv)
    bad_tex = quad()
    bad_tex.texture = np.zeros((4, 4), np.float32)
    with pytest.raises(InputError, match="texture"):
        renderer.render(bad_tex)
    with pytest.raises(InputError, match="no meshes"):
        renderer.render([])


def test_bad_options_raise_input_error(renderer):
    b = box()
    for options, match in [
        ({"size": (0, 100)}, "size"),
        ({"size": (100000, 100)}, "size"),
        ({"size": "big"}, "size"),
        ({"view": "top"}, "unknown view"),
        ({"colors": ["nocolour"]}, "unknown color"),
        ({"colors": ["red", "blue"]}, "2 colours given for 1 meshes"),
        ({"colors": "red"}, "list"),
        ({"background": (2.0, 0.0, 0.0)}, "background"),
        ({"shading": "toon"}, "shading"),
        ({"supersample": 9}, "supersample"),
        ({"samples": 2.5}, "samples"),
    ]:
        with pytest.raises(InputError, match=match):
            renderer.render(b, **options)


def test_bad_cameras_raise_input_error():
    with pytest.raises(InputError, match="coincide"):
        Camera(eye=(1.0, 1.0, 1.0), target=(1.0, 1.0, 1.0))
    with pytest.raises(InputError, match="parallel"):
        Camera(eye=(0.0, 5.0, 0.0), target=(0.0, 0.0, 0.0), up=(0.0, 1.0, 0.0))
    with pytest.raises(InputError, match="fov"):
        Camera(eye=(0.0, 0.0, 5.0), target=(0.0, 0.0, 0.0), fov_y_deg=180.0)
    with pytest.raises(InputError, match="finite"):
        Camera(eye=(0.0, np.nan, 5.0), target=(0.0, 0.0, 0.0))


def test_missing_egl_is_an_input_error_naming_the_packages(monkeypatch):
    import moderngl

    def no_egl(*args, **kwargs):
        raise Exception("libEGL.so: cannot open shared object file")  # what glcontext raises without libegl1

    monkeypatch.setattr(moderngl, "create_standalone_context", no_egl)
    with pytest.raises(InputError, match="libegl1 libgl1-mesa-dri") as err:
        Renderer()
    assert "\n" not in str(err.value)


# -- files --------------------------------------------------------------------------------------------------


def test_write_png_round_trip_and_refuses_inputs(tmp_path, renderer):
    img = renderer.render(box(), size=(64, 80), background=None)
    out = write_png(tmp_path / "sub" / "box.png", img)
    back = np.asarray(Image.open(out))
    np.testing.assert_array_equal(back, img)
    assert sorted(p.name for p in out.parent.iterdir()) == ["box.png"]  # no temporary left behind
    before = out.read_bytes()
    with pytest.raises(InputError, match="overwrite an input"):
        write_png(out, img[..., :3], inputs=[out])
    assert out.read_bytes() == before
    with pytest.raises(InputError, match="uint8"):
        write_png(tmp_path / "f.png", img.astype(np.float32))


def test_read_texture(tmp_path):
    rgba = np.zeros((8, 8, 4), np.uint8)
    rgba[..., 3] = 200
    Image.fromarray(rgba).save(tmp_path / "t.png")
    assert read_texture(tmp_path / "t.png").shape == (8, 8, 4)
    Image.fromarray(rgba[..., :3]).save(tmp_path / "t.jpg")
    assert read_texture(tmp_path / "t.jpg").shape == (8, 8, 3)
    (tmp_path / "bad.png").write_text("not an image")
    with pytest.raises(InputError, match="bad.png: not a readable image"):
        read_texture(tmp_path / "bad.png")
    with pytest.raises(InputError, match="not found"):
        read_texture(tmp_path / "missing.png")
