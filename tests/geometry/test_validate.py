import numpy as np
import trimesh

from kitsuke.body import load_body
from kitsuke.geometry import TriMesh, clean_mesh, save_mesh


def sphere_body(tmp_path, mesh):
    return save_mesh(TriMesh(mesh.vertices, mesh.faces), tmp_path / "m.obj")


def test_closed_mesh_is_watertight():
    s = trimesh.creation.icosphere(subdivisions=2)
    _, check = clean_mesh(TriMesh(s.vertices, s.faces))
    assert check.watertight and check.holes == 0 and check.non_manifold_edges == 0


def test_holes_are_counted():
    s = trimesh.creation.icosphere(subdivisions=3)
    # Cut two separate caps: faces whose centre is near the poles.
    c = s.triangles_center
    keep = (c[:, 2] < 0.9) & (c[:, 2] > -0.9)
    _, check = clean_mesh(TriMesh(s.vertices, s.faces[keep]))
    assert check.holes == 2 and not check.watertight
    assert check.removed_unreferenced_vertices > 0


def test_non_manifold_edges_are_reported():
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1.0]])
    f = np.array([[0, 1, 2], [1, 0, 3], [0, 1, 4]])  # edge 0-1 shared by three faces
    _, check = clean_mesh(TriMesh(v, f))
    assert check.non_manifold_edges == 1


def test_degenerate_and_unreferenced_are_removed_and_counted():
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [2, 0, 0], [9, 9, 9.0]])
    f = np.array([[0, 1, 2], [0, 1, 3], [1, 1, 2]])  # a zero-area sliver, a repeated index
    mesh, check = clean_mesh(TriMesh(v, f))
    assert check.removed_degenerate_faces == 2
    assert check.removed_unreferenced_vertices == 2
    assert mesh.n_faces == 1 and mesh.n_vertices == 3


def test_body_with_holes_loads_and_reports_them(tmp_path):
    from kitsuke.geometry import load_mesh

    from ..conftest import DATA

    m = load_mesh(DATA / "bodies" / "mean_all.obj")
    c = m.vertices[m.faces].mean(axis=1)
    chest = m.vertices[np.argmax(m.vertices[:, 2] - np.abs(m.vertices[:, 1] - 1.3))]
    keep = np.linalg.norm(c - chest, axis=1) > 0.04  # a round hole in the chest
    body = load_body(save_mesh(TriMesh(m.vertices, m.faces[keep]), tmp_path / "open.obj"))
    info = body.info()
    assert info["holes"] == 1 and info["watertight"] is False
