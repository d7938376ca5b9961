"""Triangle meshes: the mesh type, loading and saving, validation, units and axes."""

from .io import MESH_SUFFIXES, load_mesh, read_mesh, save_mesh
from .mesh import TriMesh
from .units import Conversion, plan_conversion
from .validate import MeshCheck, clean_mesh

__all__ = [
    "MESH_SUFFIXES",
    "Conversion",
    "MeshCheck",
    "TriMesh",
    "clean_mesh",
    "load_mesh",
    "plan_conversion",
    "read_mesh",
    "save_mesh",
]
