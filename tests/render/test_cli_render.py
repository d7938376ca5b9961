"""`kitsuke render`: PNG outputs, views, textures, and one-line errors with exit code 2."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
from PIL import Image

from .shapes import box, checker

SIZE = ["--size", "120x150"]


@pytest.fixture
def box_obj(tmp_path):
    path = tmp_path / "box.obj"
    b = box()
    lines = [f"v {x:.6f} {y:.6f} {z:.6f}" for x, y, z in b.vertices]
    lines += [f"f {a + 1} {c + 1} {d + 1}" for a, c, d in b.faces]
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.fixture
def quad_obj(tmp_path):
    """A 1 m square facing +Z with UVs covering [0, 2]^2 (so a texture repeats twice)."""
    path = tmp_path / "quad.obj"
    path.write_text(
        "v -0.5 -0.5 0\nv 0.5 -0.5 0\nv 0.5 0.5 0\nv -0.5 0.5 0\n"
        "vt 0 0\nvt 2 0\nvt 2 2\nvt 0 2\n"
        "f 1/1 2/2 3/3\nf 1/1 3/3 4/4\n"
    )
    return path


@pytest.fixture
def checker_png(tmp_path):
    path = tmp_path / "checker.png"
    Image.fromarray(checker()).save(path)
    return path


def _png(path) -> np.ndarray:
    return np.asarray(Image.open(path))


def test_render_front_png(run_cli, box_obj, tmp_path):
    out = tmp_path / "front.png"
    r = run_cli("render", box_obj, "-o", out, *SIZE, "--background", "#00ff00")
    assert r.code == 0, r.err
    assert f"wrote {out}" in r.out and "120x150" in r.out
    img = _png(out)
    assert img.shape == (150, 120, 3)
    covered = np.abs(img.astype(int) - [0, 255, 0]).max(axis=2) > 6
    assert 0.18 < covered.mean() < 0.30


def test_render_all_views_sheet(run_cli, box_obj, tmp_path):
    out = tmp_path / "sheet.png"
    r = run_cli("render", box_obj, "-o", out, *SIZE, "--view", "all")
    assert r.code == 0, r.err
    img = _png(out)
    assert img.shape[1] == 3 * 120 and img.shape[0] > 150


def test_render_texture_transparent_wireframe(run_cli, quad_obj, checker_png, tmp_path):
    out = tmp_path / "tex.png"
    r = run_cli("render", quad_obj, "-o", out, *SIZE, "--texture", checker_png, "--transparent", "--view", "back")
    assert r.code == 0, r.err
    img = _png(out).astype(int)
    assert img.shape == (150, 120, 4)
    assert img[0, 0, 3] == 0 and img[75, 60, 3] == 255  # transparent outside, opaque cloth seen from behind
    opaque = img[..., 3] == 255
    red = opaque & (img[..., 0] - img[..., 2] > 60)
    blue = opaque & (img[..., 2] - img[..., 0] > 60)
    assert red.sum() > 0.2 * opaque.sum() and blue.sum() > 0.2 * opaque.sum()


def test_wireframe_and_flat(run_cli, box_obj, tmp_path):
    plain, wire = tmp_path / "plain.png", tmp_path / "wire.png"
    assert run_cli("render", box_obj, "-o", plain, *SIZE, "--view", "three_quarter", "--flat").code == 0
    assert run_cli("render", box_obj, "-o", wire, *SIZE, "--view", "three_quarter", "--flat", "--wireframe").code == 0
    darker = _png(plain).astype(int).sum(axis=2) - _png(wire).astype(int).sum(axis=2) > 60
    assert darker.sum() > 50  # the box's edges and face diagonals


def test_colours_per_mesh(run_cli, box_obj, quad_obj, tmp_path):
    out = tmp_path / "c.png"
    r = run_cli("render", box_obj, quad_obj, "-o", out, *SIZE, "--color", "red", "blue", "--background", "black")
    assert r.code == 0, r.err
    img = _png(out).astype(int)
    assert (img[..., 2] - img[..., 0] > 60).sum() > 100  # the quad (in front of the box) is blue
    assert (img[..., 0] - img[..., 2] > 60).sum() > 100  # the box around it is red


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["missing.obj"], "missing.obj: mesh file not found"),
        (["BOX", "--size", "12"], "--size must be WIDTHxHEIGHT"),
        (["BOX", "--size", "10x100000"], "16..8192"),
        (["BOX", "--texture", "TEXTURE"], "box.obj: has no UV coordinates"),
        (["QUAD", "--texture", "missing.png"], "missing.png: texture image not found"),
        (["QUAD", "--texture", "BOX"], "box.obj: not a readable image"),
        (["BOX", "--color", "nocolour"], "unknown color 'nocolour'"),
        (["BOX", "--color", "red", "blue"], "2 colours given for 1 meshes"),
        (["BOX", "--view", "all", "--transparent"], "--transparent needs a single --view"),
        (["EMPTY"], "empty.obj"),
    ],
)
def test_bad_input_exits_2_with_one_line(run_cli, box_obj, quad_obj, checker_png, tmp_path, args, needle):
    (tmp_path / "empty.obj").write_text("# nothing\n")
    subs = {
        "BOX": str(box_obj),
        "QUAD": str(quad_obj),
        "TEXTURE": str(checker_png),
        "EMPTY": str(tmp_path / "empty.obj"),
    }
    args = [subs.get(a, str(tmp_path / a) if a.endswith((".obj", ".png")) else a) for a in args]
    out = tmp_path / "out.png"
    r = run_cli("render", *args, "-o", out)
    assert r.code == 2
    assert needle in r.err and len(r.err.strip().splitlines()) == 1 and "Traceback" not in r.err
    assert not out.exists()


def test_outputs_never_overwrite_inputs(run_cli, box_obj, quad_obj, checker_png, tmp_path):
    before = checker_png.read_bytes()
    r = run_cli("render", quad_obj, "-o", checker_png, "--texture", checker_png)
    assert r.code == 2 and "refusing to overwrite an input" in r.err
    assert checker_png.read_bytes() == before
    r = run_cli("render", box_obj, "-o", tmp_path / "view.jpg")
    assert r.code == 2 and "must end in .png" in r.err


def test_usage_errors_exit_2(run_cli, box_obj):
    assert run_cli("render").code == 2
    assert run_cli("render", box_obj).code == 2  # -o is required
    r = run_cli("render", box_obj, "-o", "x.png", "--view", "top")
    assert r.code == 2 and "invalid choice" in r.err


def test_help_teaches_views_and_examples(run_cli):
    r = run_cli("render", "--help")
    assert r.code == 0
    for text in ("--view", "--size", "--texture", "--transparent", "examples:", "front = from +Z", "800x1000"):
        assert text in r.out


def test_subprocess_run(box_obj, tmp_path):
    out = tmp_path / "p.png"
    done = subprocess.run(
        [sys.executable, "-m", "kitsuke", "render", str(box_obj), "-o", str(out), "--view", "side", *SIZE],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 0, done.stderr
    assert _png(out).shape == (150, 120, 3)
