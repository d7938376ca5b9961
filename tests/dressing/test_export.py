"""`kitsuke dress` end to end on the shipped shirt case, and the SPEC §3.3 outputs read back."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from kitsuke.dressing.export import read_garment_obj
from kitsuke.errors import InputError
from kitsuke.geometry import load_mesh
from kitsuke.pattern import load_pattern

ROOT = Path(__file__).resolve().parents[2]
SHIRT = ROOT / "tests" / "data" / "pattern" / "shirt_mean_specification.json"
MEAN_ALL = ROOT / "tests" / "data" / "bodies" / "mean_all.obj"
SHIRT_STROKES = ROOT / "src" / "kitsuke" / "assets" / "strokes" / "shirt_mean_all.json"


@pytest.fixture(scope="module")
def dressed(tmp_path_factory):
    from kitsuke.cli import main

    out = tmp_path_factory.mktemp("dress")
    files = {k: out / f"shirt.{k}" for k in ("glb", "obj", "json", "png")}
    inputs = ["--body", str(MEAN_ALL), "--pattern", str(SHIRT), "--strokes", str(SHIRT_STROKES)]
    outputs = ["-o", files["glb"], "--obj", files["obj"], "--report", files["json"], "--png", files["png"]]
    code = main(["dress", *inputs, *map(str, outputs)])
    assert code == 0
    return files


def test_obj_has_pattern_rest_shape_pieces_and_shared_seams(dressed):
    g = read_garment_obj(dressed["obj"])
    pattern = load_pattern(SHIRT)
    assert g.piece_names == [p.name for p in pattern.pieces]
    assert g.piece_faces[0, 0] == 0 and g.piece_faces[-1, 1] == len(g.faces)
    assert (g.piece_faces[1:, 0] == g.piece_faces[:-1, 1]).all()
    # vt is the pattern in metres: each piece's vt area equals the piece's area (within the meshing's 0.5 %).
    for name, (a, b) in zip(g.piece_names, g.piece_faces):
        uv = g.corner_uv[a:b]
        e1, e2 = uv[:, 1] - uv[:, 0], uv[:, 2] - uv[:, 0]
        area_m2 = 0.5 * np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]).sum()
        assert area_m2 == pytest.approx(pattern.piece(name).area * 1e-4, rel=0.005), name
    # Seams are shared vertices: fewer vertices than corners' distinct uv, and no open seam (every piece touches
    # another piece through a shared vertex).
    owner = np.full(len(g.positions), -1)
    for k, (a, b) in enumerate(g.piece_faces):
        for v in np.unique(g.faces[a:b]):
            owner[v] = k if owner[v] in (-1, k) else -2
    assert (owner == -2).sum() > 50
    # Rest lengths from vt are what the report's strain is measured against: positive and centimetre-sized, but
    # where the polish refined a fold (up to 4 sqrt(3) levels: a ninth of 1.5 cm and less; measured 0.77 mm).
    rest = g.rest_edge_lengths
    assert rest.min() > 0.0002 and 0.01 < np.median(rest) < 0.02
    assert g.contact_offset_m == pytest.approx(0.001)  # the shirt's, from `# kitsuke contact_offset_m`


def test_report_glb_and_png(dressed):
    report = json.loads(dressed["json"].read_text())
    q = report["quality"]
    assert q["penetration_count"] == 0 and q["seam_gap_mm"] == 0.0
    assert report["vertices"] == len(read_garment_obj(dressed["obj"]).positions)
    # The command's default tethers keep every stroke within 8 mm of where it was drawn (1 cm is the target).
    assert len(report["strokes"]) == 8 and max(s["residual_mm"] for s in report["strokes"]) <= 10.0
    glb = load_mesh(dressed["glb"])  # garment + body in one scene
    assert glb.n_faces == len(read_garment_obj(dressed["obj"]).faces) + load_mesh(MEAN_ALL).n_faces
    img = np.asarray(Image.open(dressed["png"]).convert("RGB")).astype(int)
    blue = (img[..., 2] > img[..., 0] + 40).mean()  # the garment's colour differs from skin and background
    assert 0.01 < blue < 0.5


def test_dress_bad_input_is_exit_2_and_writes_nothing(run_cli, tmp_path):
    strokes = json.loads(SHIRT_STROKES.read_text())
    strokes["pairs"][0]["pattern"]["piece"] = "no_such_piece"
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(strokes))
    out = tmp_path / "x.glb"
    cases = [
        (["--strokes", str(bad)], "no_such_piece"),
        (["--strokes", str(tmp_path / "missing.json")], "missing.json"),
        (["--strokes", str(SHIRT_STROKES), "--obj", str(SHIRT)], "must end in .obj"),
        (["--strokes", str(SHIRT_STROKES), "--stroke-reach", "-1"], "--stroke-reach must be between 0 and 100 mm"),
        (["--strokes", str(SHIRT_STROKES), "--hang", "-1"], "--hang must be between 0 and 10"),
        (["--strokes", str(SHIRT_STROKES), "--hang", "nan"], "--hang must be between 0 and 10"),
        (["--strokes", str(SHIRT_STROKES), "--set", "polish.roundz=0"], "no wrap setting 'polish.roundz'"),
        (["--strokes", str(SHIRT_STROKES), "--set", "polish"], "NAME=VALUE"),
        (["--strokes", str(SHIRT_STROKES), "--set", "settle.method=verlet"], "SettleSettings.method"),
        (["--strokes", str(SHIRT_STROKES), "--set", "polish.rounds=abc"], "polish.rounds takes a whole number"),
        (["--strokes", str(SHIRT_STROKES), "--set", "polish.rounds=2.5"], "polish.rounds takes a whole number"),
        (["--strokes", str(SHIRT_STROKES), "--set", "settle.release_strokes=1"], "takes True or False"),
    ]
    for extra, needle in cases:
        r = run_cli("dress", "--body", MEAN_ALL, "--pattern", SHIRT, "-o", out, *extra)
        assert r.code == 2, (extra, r.err)
        assert needle in r.err and len(r.err.strip().splitlines()) == 1 and "Traceback" not in r.err
        assert not out.exists()
    r = run_cli(
        "dress", "--body", MEAN_ALL, "--garment", SHIRT, "--strokes", SHIRT_STROKES, "-o", out, "--hold-strokes"
    )
    assert r.code == 2 and "--hold-strokes is for a wrap" in r.err and not out.exists()
    r = run_cli(
        "dress", "--body", MEAN_ALL, "--garment", SHIRT, "--strokes", SHIRT_STROKES, "-o", out, "--stroke-reach", "5"
    )
    assert r.code == 2 and "--stroke-reach is for a wrap" in r.err and not out.exists()
    r = run_cli("dress", "--body", MEAN_ALL, "--garment", SHIRT, "--strokes", SHIRT_STROKES, "-o", out, "--hang", "2")
    assert r.code == 2 and "--hang is for a wrap" in r.err and not out.exists()
    r = run_cli(
        "dress", "--body", MEAN_ALL, "--garment", SHIRT, "--strokes", SHIRT_STROKES, "-o", out, "--set", "grow.hang=1"
    )
    assert r.code == 2 and "--set changes the wrap's settings" in r.err and not out.exists()


def test_dress_without_the_polish(run_cli, tmp_path, dressed):
    """--no-polish: the wrap ends at its settle, so the garment keeps its pattern mesh's faces and the report
    names the max strain the polish would have taken down; with it (the `dressed` fixture) all targets are met."""
    out, report = tmp_path / "quick.glb", tmp_path / "quick.json"
    r = run_cli(
        "dress", "--body", MEAN_ALL, "--pattern", SHIRT, "--strokes", SHIRT_STROKES, "-o", out, "--report", report,
        "--no-polish",
    )  # fmt: skip
    assert r.code == 0, r.err
    quick, full = json.loads(report.read_text()), json.loads(dressed["json"].read_text())
    assert quick["polished"] is False and full["polished"] is True
    assert quick["faces"] < full["faces"]
    assert quick["quality"]["strain_max"] > 0.05 >= full["quality"]["strain_max"]
    assert "targets missed: max edge strain" in r.err and "all quality targets met" not in r.err
    # The same by the setting's name: the same garment.
    same = tmp_path / "same.json"
    r = run_cli(
        "dress", "--body", MEAN_ALL, "--pattern", SHIRT, "--strokes", SHIRT_STROKES, "-o", tmp_path / "same.glb",
        "--report", same, "--set", "polish.rounds=0",
    )  # fmt: skip
    assert r.code == 0, r.err
    assert json.loads(same.read_text())["quality"] == quick["quality"]


def test_dress_a_kimono_pattern_like_the_demo(run_cli, tmp_path):
    """A kimono pattern file (`kitsuke pattern kimono`) on the default body is dressed as the demo dresses it:
    sleeves hanging as bags (their lowest point far below the elbow; measured 30 / 32 cm at 2.5 cm edges, the
    size used here to keep the test short) and the waist held in the obi band (the report's pinned count)."""
    from kitsuke.body import default_body
    from kitsuke.skeleton import INDEX

    pattern, obj, report = tmp_path / "kimono.json", tmp_path / "k.obj", tmp_path / "k.json"
    assert run_cli("pattern", "kimono", "--fit-height", "1.666", "-o", pattern).code == 0
    strokes = ROOT / "src" / "kitsuke" / "assets" / "strokes" / "kimono_default.json"
    r = run_cli(
        "dress", "--body", "default", "--pattern", pattern, "--strokes", strokes, "--edge-length", "2.5",
        "-o", tmp_path / "k.glb", "--obj", obj, "--report", report,
    )  # fmt: skip
    assert r.code == 0, r.err
    g = read_garment_obj(obj)
    elbow = default_body().rig.joints[INDEX["l_elbow"], 1]
    for k, name in enumerate(g.piece_names):
        if name.startswith("sode"):
            v = np.unique(g.faces[g.piece_faces[k, 0] : g.piece_faces[k, 1]])
            assert elbow - g.positions[v, 1].min() > 0.25, name
    # The fronts' layers (left over right) travel in the OBJ's `# kitsuke layer` lines, for a later drag.
    for k, name in enumerate(g.piece_names):
        layer = g.face_layer[g.piece_faces[k, 0] : g.piece_faces[k, 1]]
        if name.startswith("okumi"):
            assert (layer == (2 if name.endswith("left") else 1)).all(), name
        elif name.startswith("sode"):
            assert not layer.any(), name
    # So does its contact offset: a kimono lies 3 mm off the body, and a drag of the file keeps it there (at 1 mm
    # the body showed through between the vertices of a dragged kimono's faces).
    assert g.contact_offset_m == pytest.approx(0.003)
    from kitsuke.dressing.drag import DragSession

    assert DragSession(default_body(), g).model.params.contact_offset_m == pytest.approx(0.003)
    summary = json.loads(report.read_text())
    assert summary["held_vertices"] > 100  # the obi band
    assert summary["quality"]["penetration_count"] == 0 and summary["quality"]["inverted_count"] == 0


def test_read_garment_obj_rejects_plain_meshes(tmp_path):
    p = tmp_path / "plain.obj"
    p.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    with pytest.raises(InputError, match="needs a vt"):
        read_garment_obj(p)


@pytest.mark.parametrize(
    "line, text",
    [
        ("# kitsuke layer two 0 0", "bad layer line"),
        ("# kitsuke layer 63 0 0", "layer 1..62"),
        ("# kitsuke layer 1 0 5", "layer 1..62"),
        ("# kitsuke contact_offset_m 3mm", "bad contact offset line"),
        ("# kitsuke contact_offset_m nan", "0 to 0.05 metres"),
        ("# kitsuke contact_offset_m -0.001", "0 to 0.05 metres"),
        ("# kitsuke contact_offset_m 3", "0 to 0.05 metres"),
    ],
    ids=["not-a-number", "too-high", "past-the-faces", "offset-unit", "offset-nan", "offset-negative", "offset-mm"],
)
def test_read_garment_obj_rejects_bad_comment_lines(tmp_path, line, text):
    p = tmp_path / "g.obj"
    p.write_text(f"{line}\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n")
    with pytest.raises(InputError, match=text) as e:
        read_garment_obj(p)
    assert "g.obj" in str(e.value)
