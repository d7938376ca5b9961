import json

from kitsuke.geometry import TriMesh, load_mesh, save_mesh

from ..conftest import DATA


def test_info_default(run_cli):
    r = run_cli("body", "info", "default")
    assert r.code == 0, r.err
    info = json.loads(r.out)
    assert info["rigged"] and info["watertight"] and info["joints"] == 23
    assert abs(info["height_m"] - 1.666) < 0.01


def test_info_reports_conversion(run_cli, tmp_path):
    m = load_mesh(DATA / "bodies" / "mean_all.obj")
    p = save_mesh(TriMesh(m.vertices * 100, m.faces), tmp_path / "cm.obj")
    r = run_cli("body", "info", p)
    info = json.loads(r.out)
    assert info["conversion"]["units"] == "cm" and info["conversion"]["applied"]
    assert abs(info["height_m"] - 1.72) < 0.01 and not info["rigged"]


def test_convert_writes_metres_and_never_overwrites_input(run_cli, tmp_path):
    m = load_mesh(DATA / "bodies" / "mean_all.obj")
    p = save_mesh(TriMesh(m.vertices * 100, m.faces), tmp_path / "cm.obj")
    before = p.read_bytes()
    r = run_cli("body", "convert", p, p)
    assert r.code == 2 and "overwrite an input" in r.err and p.read_bytes() == before
    r = run_cli("body", "convert", p, tmp_path / "m.glb")
    assert r.code == 0, r.err
    assert abs(load_mesh(tmp_path / "m.glb").vertices[:, 1].max() - 1.72) < 0.01


def test_bad_inputs_exit_2_with_one_line(run_cli, tmp_path):
    empty = tmp_path / "empty.obj"
    empty.write_text("")
    nan = tmp_path / "nan.obj"
    nan.write_text("v 0 0 nan\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    for args in (
        ("body", "info", empty),
        ("body", "info", nan),
        ("body", "info", tmp_path / "missing.ply"),
        ("body", "info", DATA / "bodies" / "mean_all.obj", "--units", "mm"),
    ):
        r = run_cli(*args)
        assert r.code == 2, args
        lines = r.err.strip().splitlines()
        assert len(lines) == 1 and "Traceback" not in r.err and str(args[2]) in lines[0], r.err
