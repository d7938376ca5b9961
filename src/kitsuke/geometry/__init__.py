"""Triangle meshes: the mesh type, loading and saving, validation, units and axes."""

from .mesh import TriMesh

__all__ = ["TriMesh"]
