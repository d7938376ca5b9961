"""The polish step's last turns (`_polish_step.polish_step`): the untangle opens the folds the polish left, the
strain limit takes back the stretch that opening left, and where the limit folds a triangle again the untangle
opens it and the limit runs once more; the cloth kept is the limited one that folds nothing, else the least
strained cloth that folds nothing.

The polish, the untangle and the limit are stood in for here (their own tests are in tests/cloth): each fake
moves one corner of a small sheet by a set amount, and a fold is marked by lifting another corner, so the test
follows the step's choices, not the solvers'."""

from __future__ import annotations

import numpy as np
import pytest

import kitsuke.dressing._polish_step as step
from kitsuke.cloth import ClothModel, ClothState
from kitsuke.cloth._polish import PolishStats, RefinedPolish
from kitsuke.cloth._shapes import grid_sheet
from kitsuke.dressing._polish_step import PolishSettings, polish_step
from kitsuke.metrics import strain

FOLD = 0  # vertex lifted 1 m to mark the cloth folded
PULLED = 8  # the far corner, pulled out along x to stretch its edges


def _sheet() -> tuple[ClothModel, ClothState]:
    uv, faces = grid_sheet(3, 3, 0.01)
    model = ClothModel.from_corners(faces, uv[faces])
    return model, ClothState.new(model, np.c_[uv, np.zeros(len(uv))])


def _rigged(monkeypatch, model, state, untangle_pulls_mm, limit_folds):
    """Stand-ins for the polish (leaves the cloth folded), the untangle (opens it, pulling the corner out by the
    next of `untangle_pulls_mm`) and the limit (puts the corner back; folds again while `limit_folds` says so).
    Returns the calls made, in order."""
    calls = []
    rest = state.positions[PULLED].copy()

    def polish_refined(model, trial, collider, **_):
        trial.positions[FOLD, 2] = 1.0
        return RefinedPolish(model, trial, np.arange(model.n_faces), {}, 0, PolishStats())

    def folded_faces(model, state):
        return np.full(model.n_faces, state.positions[FOLD, 2] > 0.5)

    def untangle(model, state, collider, **_):
        pull = untangle_pulls_mm[sum(c == "untangle" for c in calls)]
        calls.append("untangle")
        state.positions[FOLD, 2] = 0.0
        state.positions[PULLED] = rest + [pull * 1e-3, 0.0, 0.0]

    def cap_strain(model, state, collider, limit, **_):
        folds = limit_folds[sum(c == "limit" for c in calls)]
        calls.append("limit")
        state.positions[PULLED] = rest
        state.positions[FOLD, 2] = 1.0 if folds else 0.0
        return True

    for name, fake in (("polish_refined", polish_refined), ("folded_faces", folded_faces), ("untangle", untangle),
                       ("cap_strain", cap_strain), ("is_better", lambda *a, **k: True)):  # fmt: skip
        monkeypatch.setattr(step, name, fake)
    return calls


def _max_strain(model: ClothModel, state: ClothState) -> float:
    return strain(state.positions, model.edges, model.rest_lengths).max


def test_what_the_limit_folds_is_opened_and_limited_again(monkeypatch):
    """A tiered skirt's refined 1.7 mm edge: opening the last folds stretched it to 11.4 %, and the limit that
    took that back folded one triangle, so the stretched cloth was kept; opened and limited again, it ends
    limited and unfolded."""
    model, state = _sheet()
    calls = _rigged(monkeypatch, model, state, untangle_pulls_mm=[3, 2, 4], limit_folds=[True, True, False])
    _, rp = polish_step(model, state, None, PolishSettings())
    assert calls == ["untangle", "limit"] * 3
    assert rp.state.positions[FOLD, 2] == 0.0 and _max_strain(rp.model, rp.state) == pytest.approx(0.0, abs=1e-12)


def test_when_the_limit_always_folds_the_least_strained_unfolded_cloth_is_kept(monkeypatch):
    model, state = _sheet()
    calls = _rigged(monkeypatch, model, state, untangle_pulls_mm=[3, 2, 4], limit_folds=[True, True, True])
    _, rp = polish_step(model, state, None, PolishSettings())
    assert calls == ["untangle", "limit"] * step.UNFOLD_LIMIT_TURNS
    assert rp.state.positions[FOLD, 2] == 0.0
    assert rp.state.positions[PULLED, 0] - state.positions[PULLED, 0] == pytest.approx(2e-3)  # the 2 mm turn
    # The step worked on a copy: the cloth given is as it was.
    assert state.positions[FOLD, 2] == 0.0 and _max_strain(model, state) == 0.0


def test_a_limit_that_folds_nothing_ends_the_turns(monkeypatch):
    model, state = _sheet()
    calls = _rigged(monkeypatch, model, state, untangle_pulls_mm=[3], limit_folds=[False])
    _, rp = polish_step(model, state, None, PolishSettings())
    assert calls == ["untangle", "limit"] and _max_strain(rp.model, rp.state) == pytest.approx(0.0, abs=1e-12)


def test_a_turn_that_gains_nothing_is_the_last(monkeypatch):
    """Turns cost an untangle and a limit each (seconds on a large garment): they go on only while the opened
    cloth gets less strained."""
    model, state = _sheet()
    calls = _rigged(monkeypatch, model, state, untangle_pulls_mm=[3, 4, 1], limit_folds=[True, True, True])
    _, rp = polish_step(model, state, None, PolishSettings())
    assert calls == ["untangle", "limit"] * 2
    assert rp.state.positions[PULLED, 0] - state.positions[PULLED, 0] == pytest.approx(3e-3)
