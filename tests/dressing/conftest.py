"""Shared fixtures: the default body (as a reusable Surface), the standard kimono and its mesh, and the default
kimono dressed on the default body as `kitsuke demo` dresses it (one wrap, ~10 s, shared by the wrap, drag and
re-wrap tests, which only read it)."""

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


@pytest.fixture(scope="session")
def dressed_kimono(body):
    from kitsuke.dressing.kimono import dress_default_kimono

    return dress_default_kimono(body)
