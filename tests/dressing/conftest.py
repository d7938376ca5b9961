"""Shared fixtures: the default body (as a reusable Surface), the standard kimono and its mesh."""

from __future__ import annotations

import pytest

from kitsuke.body import default_body
from kitsuke.geometry.surface import Surface
from kitsuke.pattern import make_kimono, mesh_pattern


@pytest.fixture(scope="session")
def body():
    return default_body()


@pytest.fixture(scope="session")
def body_surface(body):
    return Surface(body.mesh)


@pytest.fixture(scope="session")
def kimono():
    return make_kimono()


@pytest.fixture(scope="session")
def kimono_mesh(kimono):
    return mesh_pattern(kimono, edge_length=3.0)
