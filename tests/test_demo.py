"""`kitsuke demo` writes every promised file, and each is a real, readable, non-empty result."""

import json

import numpy as np
import pytest
import trimesh
from PIL import Image

from kitsuke.body import default_body
from kitsuke.dressing.export import read_garment_obj
from kitsuke.geometry import load_mesh
from kitsuke.pattern import load_pattern


@pytest.mark.slow
def test_demo_writes_real_files(run_cli, tmp_path):
    out = tmp_path / "out"
    r = run_cli("demo", "--out", out, "--size", "200x250")
    assert r.code == 0, r.err
    names = sorted(p.name for p in out.iterdir())
    assert names == sorted(
        [
            "body.glb",
            "kimono.json",
            "kimono.svg",
            "kimono.png",
            "kimono_textured.png",
            "kimono.obj",
            "body_front.png",
            "body_side.png",
            "kimono_on_stand.png",
            "dressed.glb",
            "dressed.obj",
            "dressed_report.json",
            "dressed.png",
        ]
    )
    body = load_mesh(out / "body.glb")
    assert body.n_vertices == default_body().mesh.n_vertices
    kimono = load_pattern(out / "kimono.json")
    assert len(kimono.pieces) == 7 and len(kimono.seams) == 21
    assert load_mesh(out / "kimono.obj").n_faces > 10_000
    assert "<svg" in (out / "kimono.svg").read_text()[:500]
    masks = {}
    for name in ("body_front.png", "body_side.png", "kimono_on_stand.png"):
        img = np.asarray(Image.open(out / name).convert("RGB")).astype(int)
        assert img.shape == (250, 200, 3)
        # The subject: pixels far from the background, a vertical gradient, so compared with the row's left edge.
        masks[name] = np.abs(img - img[:, :1]).sum(axis=2) > 40
        assert 0.05 < masks[name].mean() < 0.8, name

    # The front view is much wider than the side view (arms out to the sides).
    def width(m):
        return np.ptp(np.nonzero(m.any(axis=0))[0])

    assert width(masks["body_front.png"]) > 1.3 * width(masks["body_side.png"])
    # The kimono covers more of the frame than the bare body.
    assert masks["kimono_on_stand.png"].mean() > 1.5 * masks["body_front.png"].mean()
    # The dressed kimono: read back, on the body, with its quality report.
    dressed = read_garment_obj(out / "dressed.obj")
    assert len(dressed.piece_names) == 7 and dressed.positions[:, 1].max() > 1.3
    report = json.loads((out / "dressed_report.json").read_text())
    q = report["quality"]
    assert q["penetration_count"] == 0 and q["seam_gap_mm"] == 0.0 and q["strain_mean"] < 0.025
    glb = trimesh.load(out / "dressed.glb")
    assert len(glb.geometry) == 2  # garment and body
    sheet = np.asarray(Image.open(out / "dressed.png").convert("RGB"))
    assert sheet.shape[1] > 2 * sheet.shape[0]  # front, side and back side by side


def test_demo_bad_size_is_exit_2(run_cli, tmp_path):
    r = run_cli("demo", "--out", tmp_path / "o", "--size", "big")
    assert r.code == 2 and "--size" in r.err and not (tmp_path / "o").exists()
