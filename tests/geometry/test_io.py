import shutil

import numpy as np
import pytest

from kitsuke.errors import InputError
from kitsuke.geometry import TriMesh, clean_mesh, load_mesh, read_mesh, save_mesh

from ..conftest import DATA, GLTF_VALIDATOR, gltf_report


def quad_obj(tmp_path, text):
    p = tmp_path / "m.obj"
    p.write_text(text)
    return p


def test_obj_quads_are_triangulated_and_negative_indices_work(tmp_path):
    p = quad_obj(tmp_path, "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\nf -4 -2 -1\n")
    mesh, n_poly = read_mesh(p)
    assert n_poly == 1
    assert mesh.faces.tolist() == [[0, 1, 2], [0, 2, 3], [0, 2, 3]]
    cleaned, check = clean_mesh(mesh)
    assert check.removed_duplicate_faces == 1 and cleaned.n_faces == 2


def test_obj_group_selection_drops_other_groups(tmp_path):
    text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 5 5 5\nv 6 5 5\nv 5 6 5\ng body\nf 1 2 3\ng helper\nf 4 5 6\n"
    mesh = load_mesh(quad_obj(tmp_path, text), group="body")
    assert mesh.n_faces == 1 and mesh.n_vertices == 3  # the helper's vertices are unreferenced, removed
    with pytest.raises(InputError, match="no group 'skin'"):
        load_mesh(quad_obj(tmp_path, text), group="skin")


def test_roundtrip_obj_glb_ply_keeps_geometry(tmp_path):
    body = load_mesh(DATA / "bodies" / "mean_all.obj")
    for suffix in (".obj", ".glb", ".ply"):
        out = save_mesh(body, tmp_path / f"b{suffix}")
        back = load_mesh(out)
        assert back.n_faces == body.n_faces, suffix
        assert back.n_vertices == body.n_vertices, suffix
        np.testing.assert_allclose(np.sort(back.vertices, axis=0), np.sort(body.vertices, axis=0), atol=2e-6)


def test_glb_of_a_textured_and_a_plain_mesh_reads_back_and_passes_the_khronos_validator(tmp_path):
    """kitsuke writes its GLBs itself: names, normals, uv and an embedded texture, read back by trimesh as other
    tools read them, and valid for the Khronos validator (where `.ci/run` installed it)."""
    body = load_mesh(DATA / "bodies" / "mean_all.obj")
    checker = np.kron([[0, 255], [255, 0]], np.ones((8, 8)))[..., None].repeat(3, axis=2).astype(np.uint8)
    cloth = TriMesh(
        [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], [[0, 1, 2], [0, 2, 3]], uv=[[0, 0], [2, 0], [2, 2], [0, 2]],
        name="cloth", texture=checker,
    )  # fmt: skip
    path = save_mesh([body, cloth], tmp_path / "scene.glb")
    import trimesh

    scene = trimesh.load(path)
    assert set(scene.geometry) == {body.name, "cloth"}
    back = scene.geometry["cloth"]
    np.testing.assert_allclose(back.vertices, cloth.vertices, atol=1e-6)
    np.testing.assert_allclose(back.visual.uv, cloth.uv, atol=1e-6)  # flipped to glTF's origin and back
    assert np.asarray(back.visual.material.baseColorTexture).shape[:2] == checker.shape[:2]
    if GLTF_VALIDATOR.exists() and shutil.which("node"):
        report = gltf_report(path)
        assert report["errors"] == 0 and report["warnings"] == 0, report["messages"]


def test_uv_survives_obj_roundtrip(tmp_path):
    m = TriMesh([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]], uv=[[0, 0], [1, 0], [0, 1]])
    back = load_mesh(save_mesh(m, tmp_path / "t.obj"))
    np.testing.assert_allclose(back.uv, m.uv)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("", "empty"),
        ("# only a comment\n", "no vertices"),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n", "does not exist"),  # truncated: faces past the vertices
        ("v 0 0 0\nv 1 0\nv 0 1 0\nf 1 2 3\n", "three numbers"),
        ("v 0 0 nan\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "NaN"),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\n", "empty"),  # no faces
        ("v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n", "degenerate"),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n", "bad face index"),
    ],
)
def test_bad_obj_is_a_clear_input_error(tmp_path, text, message):
    p = quad_obj(tmp_path, text)
    with pytest.raises(InputError, match=message) as e:
        load_mesh(p)
    assert str(p) in str(e.value)


def test_unsupported_and_garbage_files(tmp_path):
    with pytest.raises(InputError, match="unsupported mesh format"):
        load_mesh(_write(tmp_path / "m.fbx", b"x"))
    with pytest.raises(InputError, match="cannot read as GLB|holds no triangle mesh"):
        load_mesh(_write(tmp_path / "m.glb", b"glTF garbage that is not a real binary container"))
    with pytest.raises(InputError, match="not found"):
        load_mesh(tmp_path / "missing.obj")


def _write(p, data):
    p.write_bytes(data)
    return p


@pytest.mark.parametrize("form", ["{v}", "{v}/{v}", "{v}/{v}/1", "{v}//1"])
def test_obj_plain_triangles_read_at_once_match_the_line_by_line_reader(tmp_path, form):
    """Files of plain triangles take a vectorised path; one relative index sends the file down the line-by-line
    one: both must agree face for face, uv for uv, group for group."""
    from kitsuke.geometry.obj import read_obj

    head = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\n"
    tri = [(1, 2, 3), (1, 3, 4), (2, 3, 4)]
    faces = ["f " + " ".join(form.format(v=i) for i in t) for t in tri]
    plain = quad_obj(tmp_path, head + "g a\n" + faces[0] + "\n" + faces[1] + "\ng b\n" + faces[2] + "\n")
    fast = read_obj(plain)
    slow_text = plain.read_text().replace(faces[2], "f " + " ".join(form.format(v=i - 5) for i in tri[2]))
    slow = read_obj(quad_obj(tmp_path, slow_text))
    np.testing.assert_array_equal(fast.faces, [[0, 1, 2], [0, 2, 3], [1, 2, 3]])
    np.testing.assert_array_equal(fast.faces, slow.faces)
    np.testing.assert_array_equal(fast.face_group, slow.face_group)
    assert fast.groups == slow.groups == ["default", "a", "b"]
    if fast.face_uv is not None:
        np.testing.assert_array_equal(fast.face_uv, slow.face_uv)
