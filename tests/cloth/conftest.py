"""Cloth test fixtures: small sheets, an icosphere body, the default body's collider."""

from __future__ import annotations

import numpy as np
import pytest

from kitsuke.cloth import BodyCollider, ClothModel, ClothParams, grid_sheet
from kitsuke.geometry import TriMesh


def icosphere(radius: float = 0.1, subdivisions: int = 3, centre=(0.0, 0.0, 0.0)) -> TriMesh:
    import trimesh

    s = trimesh.creation.icosphere(subdivisions=subdivisions, radius=radius)
    return TriMesh(np.asarray(s.vertices) + np.asarray(centre), np.asarray(s.faces), name="sphere")


def flat_sheet(nx=8, ny=6, spacing=0.02, **params) -> tuple[ClothModel, np.ndarray]:
    """A sheet in the z = 0 plane at rest, and its positions."""
    uv, f = grid_sheet(nx, ny, spacing)
    model = ClothModel.from_flat(f, uv, params=ClothParams(**params))
    return model, np.c_[uv, np.zeros(len(uv))]


@pytest.fixture(scope="session")
def sphere() -> TriMesh:
    return icosphere()


@pytest.fixture(scope="session")
def sphere_collider(sphere) -> BodyCollider:
    return BodyCollider.from_mesh(sphere)


@pytest.fixture(scope="session")
def body():
    from kitsuke.body import default_body

    return default_body()


@pytest.fixture(scope="session")
def body_collider(body) -> BodyCollider:
    return BodyCollider.from_body(body)


@pytest.fixture
def rng():
    return np.random.default_rng(7)
