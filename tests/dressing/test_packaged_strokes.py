"""The stroke files shipped in the package (src/kitsuke/assets/strokes/), each wrapped end to end on its body:
GarmentCode's shirt and hoody on mean_all, the FreeSewing T-shirt (sewn by tools/make_tshirt_strokes.py) on the
default body (the kimono on the default body, with its obi band, is in test_wrap.py). Each case asserts its
measured quality (SPEC §6) with a small margin, so a change that makes a shipped case worse fails here.

Issue 3's targets: penetration (none deeper than 2 mm), seam gap (≤ 3 mm), no inverted triangle, mean strain
(≤ 1 %), stroke residual (≤ 10 mm, since the wrap tethers its strokes) and max strain (≤ 5 %) are met and asserted
for every case here, and for the kimono in test_wrap.py."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

from kitsuke.body import default_body, load_body
from kitsuke.dressing import TetherSettings, check_strokes, load_packaged_strokes
from kitsuke.dressing.wrap import DressedGarment, WrapParams, wrap
from kitsuke.pattern import load_pattern

ROOT = Path(__file__).resolve().parents[2]
DATA = ROOT / "tests" / "data"


@dataclass(frozen=True)
class Case:
    """A shipped stroke file, its pattern and body, and the bounds its wrap is held to (measured values in the
    comments of CASES)."""

    strokes: str  # packaged stroke file name, without .json
    pattern: Path
    body: Path | None  # None: the default body
    y_range: tuple[float, float, float, float]  # garment lowest y in [a, b], highest y in [c, d] (metres)


CASES = {
    # measured 2026-11-25 (Chebyshev finish): 0.82 % / 30 %.
    # measured 2026-11-24: strain 0.87 % / 30 %, 0 inverted, residual 8.6 mm (21 mm without the stroke tethers),
    # deepest 1.0 mm (before the length restoration: 1.43 % / 33 %, 18 mm; before the finish step: 2.13 % / 44 %)
    "shirt": Case(
        "shirt_mean_all",
        DATA / "pattern" / "shirt_mean_specification.json",
        DATA / "bodies" / "mean_all.obj",
        (0.95, 1.10, 1.38, 1.50),
    ),
    # measured 2026-11-25 (Chebyshev finish): 0.83 % / 25 %.
    # measured 2026-11-24: strain 0.87 % / 29 % (before the length restoration 1.41-1.56 % / 30-59 %, moving
    # with the installed libraries' versions), 0 inverted, residual 8.4 mm (22 mm without the stroke tethers: the
    # hood hangs behind the head), the hood reaching over the top of the head
    "hoody": Case(
        "hoody_mean_all",
        DATA / "pattern" / "hoody_mean_specification.json",
        DATA / "bodies" / "mean_all.obj",
        (0.92, 1.10, 1.66, 1.78),
    ),
    # measured 2026-11-25 (polish): 0.45 % / 3.1 %, residual 8.0 mm; (Chebyshev finish, no polish): 0.38 % / 12 %.
    # measured 2026-11-24: strain 0.46 % / 26 %, 0 inverted, residual 8.2 mm (15 mm without the stroke tethers),
    # no vertex inside (cut for a 110 cm chest on an 84 cm one: it hangs loose to the thighs)
    "tshirt": Case(
        "tshirt_default",
        DATA / "pattern" / "teagan_tshirt_cisMaleAdult42_sewn.json",
        None,
        (0.65, 0.85, 1.35, 1.47),
    ),
}


@pytest.fixture(scope="module", params=sorted(CASES))
def dressed(request) -> tuple[Case, DressedGarment]:
    case = CASES[request.param]
    body = default_body() if case.body is None else load_body(case.body)
    strokes = load_packaged_strokes(case.strokes)
    return case, wrap(body, load_pattern(case.pattern), strokes)


def test_packaged_files_are_valid_and_length_matched():
    """Every shipped file reads, names pieces and points that exist on its pattern, and asks for no stretch: each
    body stroke is as long as its pattern stroke (within 1 %; the wrap measures it on the surface)."""
    for case in CASES.values():
        strokes = load_packaged_strokes(case.strokes)
        assert len(strokes.pairs) >= 4 and strokes.target == "body"
        check_strokes(strokes, load_pattern(case.pattern))


def test_wrap_quality(dressed):
    _, g = dressed
    r = g.report
    assert np.isfinite(g.positions).all()
    assert r.penetration_count == 0 and r.penetration_deepest_mm <= 2.0
    assert r.seam_gap_mm <= 3.0
    assert r.inverted_count == 0
    np.testing.assert_allclose(g.stroke_length_ratio, 1.0, atol=0.01)
    assert g.mend.torn_before == 0  # the close leaves no edge over twice its length: nothing was regrown


def test_garment_sits_where_it_should(dressed):
    """It hangs from the shoulders (the hood over the head) and covers the chest: not slid down, not floating."""
    case, g = dressed
    y = g.positions[:, 1]
    lo_a, lo_b, hi_a, hi_b = case.y_range
    assert lo_a < y.min() < lo_b and hi_a < y.max() < hi_b


def test_mean_strain_target(dressed):
    """Issue 3's mean edge strain target, met since the wrap ends with edge-length restoration."""
    _, g = dressed
    assert g.report.strain_mean <= 0.01


def test_stroke_residual_target(dressed):
    """Issue 3: every pattern stroke lies within 1 cm of its body stroke after wrap and settle (the wrap's
    tethers hold them within 8 mm; measured 8.2-8.6 mm, the samples between vertices a little farther)."""
    _, g = dressed
    assert g.max_stroke_residual_m <= 0.01
    assert len(g.stroke_residual_m) == len(g.stroke_ids) >= 4


def test_without_tethers_the_garment_settles_away_from_its_strokes():
    """What the tethers are for: the T-shirt wrapped with `stroke_reach_m=None` rests where gravity and its ease
    put it, its strokes farther than 1 cm from where they were drawn (measured 2026-11-24: 14.9 mm)."""
    case = CASES["tshirt"]
    g = wrap(
        default_body(),
        load_pattern(case.pattern),
        load_packaged_strokes(case.strokes),
        params=WrapParams(tethers=TetherSettings(reach_m=None)),
    )
    assert g.max_stroke_residual_m > 0.012
    assert g.report.penetration_count == 0 and g.report.inverted_count == 0


def test_max_strain_target(dressed):
    """Issue 3's max edge strain target (5 %), met by all three since the polish caps strain at 4.5 % and refines
    where it folds, with the cloth 1 mm off the body (measured 2026-11-25: shirt 4.5 %, hoody 3.4 %, T-shirt
    3.7 %; with the polish as it was, at 3 mm: 29 %, 25 %, 3.1 %)."""
    _, g = dressed
    assert g.report.strain_max <= 0.05
    assert g.polished


@pytest.mark.slow
def test_held_strokes_meet_the_residual_target():
    """`WrapParams.strokes_held()`: the garment hangs from its strokes instead of settling away from them. On the
    T-shirt the residual and mean strain targets are met (measured 2026-11-24: residual 6.5 mm, mean strain
    0.77 %; 8.2 mm and 0.46 % with the default tethers), and nothing else suffers."""
    case = CASES["tshirt"]
    g = wrap(
        default_body(),
        load_pattern(case.pattern),
        load_packaged_strokes(case.strokes),
        params=WrapParams.strokes_held(),
    )
    r = g.report
    assert g.max_stroke_residual_m <= 0.01 and r.strain_mean <= 0.01
    assert r.penetration_count == 0 and r.seam_gap_mm == 0.0 and r.inverted_count == 0
