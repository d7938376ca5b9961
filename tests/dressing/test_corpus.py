"""The wrap on GarmentCode designs nobody tuned for (tests/data/pattern/corpus), from suggested strokes changed as
a hand would draw them: every outcome is honest. A result is either a garment on the body (written, with the
targets it misses said) or a ComputationError naming what failed; never garbage passed off as a garment. The
share within targets is measured by benchmarks/bench_corpus.py on other seeds (BENCHMARKS.md)."""

from __future__ import annotations

import zlib

import numpy as np
import pytest

from kitsuke.body import load_body
from kitsuke.cloth import BodyCollider
from kitsuke.dressing import DragSession, on_body_failures, perturb_strokes, suggest_strokes, target_misses, wrap
from kitsuke.errors import ComputationError
from kitsuke.metrics import QualityTargets
from kitsuke.pattern import load_pattern

from ..conftest import DATA

CORPUS = sorted((DATA / "pattern" / "corpus").glob("*_specification.json"))
#: Designs that meet every corpus target, each by a mechanism of its own (measured 2026-11-27 and 2026-11-28 on two
#: machines): the flared skirt gc_s7741_0009, draped (max strain 4.9 %); the cuffed trousers gc_s101_0006, their
#: legs gathered into the cuffs (4.5 %, mean 0.8 %; out of target sewn ungathered); and the shirt gc_s2718_0026,
#: torn round the arm when grown, dressed with every piece laid (4.5 %). Which of the others meet them moves
#: between machines and versions, as the wrap is sensitive to rounding: they are held to honest outcomes only.
WITHIN_TARGETS = {"gc_s7741_0009", "gc_s101_0006", "gc_s2718_0026"}


@pytest.fixture(scope="module")
def mean_all():
    body = load_body(DATA / "bodies" / "mean_all.obj")
    collider = BodyCollider.from_body(body)
    return body, collider, collider.surface_for(body.mesh)


def _outcome(body, collider, surface, path) -> str:
    """Dress one corpus design from its perturbed suggested strokes; "within", "written" or "failed", after
    checking that the outcome is honest."""
    name = path.stem.replace("_specification", "")
    pattern = load_pattern(path)
    strokes = perturb_strokes(
        suggest_strokes(body, pattern, surface=surface), surface, np.random.default_rng(zlib.crc32(name.encode()))
    )
    try:
        garment = wrap(body, pattern, strokes, collider=collider)
    except ComputationError as e:
        assert e.stage.startswith("wrap") and e.message, name
        assert e.result is None or on_body_failures(e.result, body, surface=surface), name
        return "failed"
    # Written: a garment on the body, finite, nowhere torn, every stroke's cloth near it.
    assert on_body_failures(garment, body, surface=surface) == [], name
    assert np.isfinite(garment.positions).all() and garment.report.strain_max < 1.0, name
    if garment.girth is not None:  # cloth round the body is at least the body's tape girth there
        assert garment.girth.worn_m >= 0.98 * garment.girth.body_m > 0.3, (name, garment.girth)
    if garment.gathers:  # a later drag rests the cloth gathered, as the wrap did
        drag = DragSession(body, garment, collider=collider)
        np.testing.assert_array_equal(drag.model.rest_lengths, garment.model.rest_lengths)
    return "within" if not target_misses(garment, QualityTargets.robust()) else "written"


@pytest.mark.slow
@pytest.mark.parametrize("path", CORPUS, ids=lambda p: p.stem.replace("_specification", ""))
def test_corpus_design_dresses_or_fails_honestly(mean_all, path):
    """One test per design, so that a parallel run spreads them (the slowest takes about a minute)."""
    outcome = _outcome(*mean_all, path)
    if path.stem.replace("_specification", "") in WITHIN_TARGETS:
        assert outcome == "within"


def test_the_designs_said_to_meet_the_targets_are_in_the_corpus():
    assert WITHIN_TARGETS <= {p.stem.replace("_specification", "") for p in CORPUS}
