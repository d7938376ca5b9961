"""Fixtures for the pattern tests: the in-repo pattern files, loaded once, and a tiny pattern builder."""

from __future__ import annotations

import pytest

from tests.conftest import DATA

PATTERNS = DATA / "pattern"
SHIRT = PATTERNS / "shirt_mean_specification.json"
HOODY = PATTERNS / "hoody_mean_specification.json"
TEAGAN = PATTERNS / "teagan_tshirt_cisMaleAdult42.svg"


@pytest.fixture(scope="session")
def shirt():
    from kitsuke.pattern import load_pattern

    return load_pattern(SHIRT)


@pytest.fixture(scope="session")
def hoody():
    from kitsuke.pattern import load_pattern

    return load_pattern(HOODY)


@pytest.fixture(scope="session")
def teagan():
    from kitsuke.pattern import load_pattern

    return load_pattern(TEAGAN)


@pytest.fixture(scope="session")
def kimono():
    from kitsuke.pattern import make_kimono

    return make_kimono()


def two_squares(**seam) -> dict:
    """A valid kitsuke JSON dict: two 10 cm squares sewn along one edge (override seam fields with kwargs)."""
    s = {"a": {"piece": "left", "edge": 1}, "b": {"piece": "right", "edge": 3}, "reversed": True}
    s.update(seam)
    return {
        "format": "kitsuke.pattern",
        "version": 1,
        "units": "cm",
        "name": "squares",
        "pieces": [
            {"name": "left", "outline": [[0, 0], [10, 0], [10, 10], [0, 10]]},
            {
                "name": "right",
                "outline": [[0, 0], [10, 0], [10, 10], [0, 10]],
                "curves": {"0": {"type": "quadratic", "control": [[0.5, 0.3]]}},
            },
        ],
        "seams": [s],
    }
