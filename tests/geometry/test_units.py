import numpy as np
import pytest

from kitsuke.body import default_body, load_body
from kitsuke.errors import InputError
from kitsuke.geometry import TriMesh, load_mesh, save_mesh

from ..conftest import DATA

# Y up, facing +Z  ->  Blender's Z up, facing -Y: (x, y, z) -> (x, -z, y)
TO_Z_UP = np.array([[1.0, 0, 0], [0, 0, -1], [0, 1, 0]])


def bodies():
    return {
        "mean_all": load_mesh(DATA / "bodies" / "mean_all.obj"),
        "default": default_body().mesh,
    }


@pytest.mark.parametrize("name", ["mean_all", "default"])
@pytest.mark.parametrize(("unit", "per_m"), [("cm", 100.0), ("dm", 10.0), ("in", 1 / 0.0254), ("mm", 1000.0)])
@pytest.mark.parametrize("z_up", [False, True])
def test_rescaled_and_turned_body_comes_back(tmp_path, name, unit, per_m, z_up):
    original = bodies()[name]
    v = original.vertices * per_m
    if z_up:
        v = v @ TO_Z_UP.T
    path = save_mesh(TriMesh(v, original.faces), tmp_path / f"{name}.obj")
    body = load_body(path)
    assert body.conversion.units == unit
    assert body.conversion.up == ("+z" if z_up else "+y")
    assert body.conversion.facing == ("-y" if z_up else "+z")
    np.testing.assert_allclose(body.mesh.vertices, original.vertices, atol=1e-6, rtol=0)


def test_upside_down_and_backwards_bodies_are_detected(tmp_path):
    original = load_mesh(DATA / "bodies" / "mean_all.obj")
    flip = np.diag([-1.0, -1.0, 1.0])  # head down (a proper rotation: 180 degrees about Z)
    turn = np.diag([-1.0, 1.0, -1.0])  # facing -Z (180 degrees about Y)
    for rot, up, facing in ((flip, "-y", "+z"), (turn, "+y", "-z")):
        path = save_mesh(TriMesh(original.vertices @ rot.T, original.faces), tmp_path / "b.obj")
        body = load_body(path)
        assert (body.conversion.up, body.conversion.facing) == (up, facing)
        np.testing.assert_allclose(body.mesh.vertices, original.vertices, atol=1e-6)


def test_overrides_win_over_detection(tmp_path):
    original = load_mesh(DATA / "bodies" / "mean_all.obj")
    path = save_mesh(TriMesh(original.vertices * 0.5, original.faces), tmp_path / "child.obj")  # 0.86 "units"
    assert load_body(path).conversion.units == "m"
    assert load_body(path, units="m").height_m == pytest.approx(0.86, abs=0.01)
    with pytest.raises(InputError, match="tall after conversion"):
        load_body(path, units="mm")


def test_a_giant_fits_no_unit(tmp_path):
    original = load_mesh(DATA / "bodies" / "mean_all.obj")
    path = save_mesh(TriMesh(original.vertices * 1e5, original.faces), tmp_path / "giant.obj")
    with pytest.raises(InputError, match="fits no unit"):
        load_body(path)
