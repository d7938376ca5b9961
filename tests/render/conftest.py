"""Render test fixtures: one OpenGL context shared by the whole session (creating one takes ~0.1-0.9 s)."""

from __future__ import annotations

import pytest


@pytest.fixture(scope="session")
def renderer():
    from kitsuke.render import Renderer

    with Renderer() as r:
        yield r
