"""Every reader survives mutated files: success or one line of InputError naming the file, within 10 s and 2 GB.

CI runs a fixed, small number of cases per reader (derandomized); `benchmarks/fuzz_inputs.py` runs 10^4.
"""

from __future__ import annotations

import json

import pytest
from hypothesis import HealthCheck, given, settings

from .harness import TARGETS, Worker, run_case
from .strategies import cases, seeds

pytestmark = pytest.mark.slow

EXAMPLES = 50


@pytest.fixture(scope="module")
def worker():
    w = Worker()
    yield w
    w.close()


@pytest.mark.parametrize("target", sorted(TARGETS))
def test_seed_files_read(target, tmp_path):
    """The unmutated seeds are valid: the fuzzing starts from files that work."""
    for data in seeds(target):
        outcome = run_case(target, data, str(tmp_path))
        assert outcome.status == "ok", outcome.detail


@pytest.mark.parametrize("target", sorted(TARGETS))
def test_mutated_files(target, worker):
    @settings(
        max_examples=EXAMPLES,
        deadline=None,
        derandomize=True,
        database=None,
        suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
    )
    @given(data=cases(target))
    def check(data):
        outcome = worker.run(target, data)
        assert outcome.fine, f"{outcome.status}: {outcome.detail}"

    check()


# -- regressions: findings of the fuzzing, each as its smallest file ----------------------------------------------
def _shirt() -> dict:
    from .harness import DATA

    return json.loads((DATA / "pattern" / "shirt_mean_specification.json").read_text())


def _circle_edge(spec: dict, radius: float, large_arc: bool) -> dict:
    panel = next(iter(spec["pattern"]["panels"].values()))
    panel["edges"][0]["curvature"] = {"type": "circle", "params": [radius, large_arc, False]}
    return spec


def test_zero_length_circle_edge_in_garmentcode(tmp_path):
    spec = _shirt()
    panel = next(iter(spec["pattern"]["panels"].values()))
    panel["vertices"][1] = list(panel["vertices"][0])
    panel["edges"][0]["curvature"] = {"type": "circle", "params": [10.0, False, False]}
    outcome = run_case("pattern-garmentcode", json.dumps(spec).encode(), str(tmp_path))
    assert outcome.status == "input-error" and "zero length" in outcome.detail, outcome


@pytest.mark.parametrize("large_arc", [False, True])
def test_huge_circle_edge_is_refused_quickly(worker, large_arc):
    """A GarmentCode circle edge of radius 10^9 cm hung the mesher: the large arc (6 * 10^4 km round) is refused
    at load, naming the limit; the small one is a straight edge to within rounding, and reads."""
    data = json.dumps(_circle_edge(_shirt(), 1e9, large_arc)).encode()
    outcome = worker.run("pattern-garmentcode", data)
    if large_arc:
        assert outcome.status == "input-error", outcome.detail
        assert "over the limit of 50 m" in outcome.detail and "--limit edge_m" in outcome.detail
    else:
        assert outcome.fine, outcome.detail
    assert outcome.seconds < 2.0


@pytest.mark.parametrize(
    ("target", "mutate", "expect"),
    [
        # an integer past float range used to raise OverflowError deep in a reader
        ("poses", lambda d: d["frames"][0].__setitem__("positions", [[10**400, 0, 0]] * 23), "NaN or infinite"),
        ("constraints", lambda d: d["knee"]["max_distance_m"].__setitem__(0, 10**400), "finite"),
        # a list where a curve type belongs: TypeError (unhashable) before
        ("pattern-kitsuke", lambda d: d["pieces"][0].__setitem__("curves", {"0": {"type": ["cubic"]}}), "curve"),
        ("pattern-kitsuke", lambda d: d.__setitem__("units", ["cm"]), "units"),
        # a circle edge of zero length: ZeroDivisionError in the size check before validation named the edge
        (
            "pattern-kitsuke",
            lambda d: (
                d["pieces"][0]["outline"].insert(1, d["pieces"][0]["outline"][0]),
                d["pieces"][0].__setitem__("curves", {"0": {"type": "circle", "control": [[0.5, 0.3]]}}),
            ),
            "zero length",
        ),
    ],
)
def test_json_regressions(target, mutate, expect, tmp_path):
    doc = json.loads(seeds(target)[0])
    mutate(doc)
    outcome = run_case(target, json.dumps(doc).encode(), str(tmp_path))
    assert outcome.status == "input-error", outcome.detail
    assert expect in outcome.detail


@pytest.mark.parametrize(
    ("target", "old", "new", "expect"),
    [
        ("body-obj", b"\nf ", b"\nf 99999999999999999999 ", "out of range"),
        ("body-obj", b"\nv ", b"\nv 1e308 ", "too large"),
    ],
)
def test_text_regressions(target, old, new, expect, tmp_path):
    data = seeds(target)[0]
    assert old in data
    outcome = run_case(target, data.replace(old, new, 1), str(tmp_path))
    assert outcome.status == "input-error", outcome.detail
    assert expect in outcome.detail


def test_svg_use_cycle_is_refused(tmp_path, worker):
    """A <use> inside the element it uses made svgelements expand forever (found by the fuzzing: swapped lines
    moved a group of FreeSewing's <defs> around its own <use>s)."""
    svg = (
        '<svg xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink" width="100mm" '
        'height="100mm" viewBox="0 0 100 100"><g id="a"><rect width="10" height="10"/>'
        '<use xlink:href="#a" x="5"/></g></svg>'
    )
    outcome = worker.run("pattern-svg", svg.encode())
    assert outcome.status == "input-error", outcome.detail
    assert "cycle" in outcome.detail


@pytest.mark.parametrize(
    ("element", "expect"),
    [
        # a transform that overflows the coordinates: NaN reached the curve sampler (ValueError) before
        ('<path transform="scale(1e308) scale(1e10)" d="M 0 0 C 5 9 9 9 10 0 L 10 10 Z"/>', "not finite"),
        ('<path d="M 0 0 L 1e12 0 L 1e12 50 Z"/>', "over the limit"),  # 10^10 m: billions of sampled points
    ],
)
def test_svg_curves_checked_before_sampling(element, expect, tmp_path):
    svg = '<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="100mm" viewBox="0 0 100 100">'
    outcome = run_case("pattern-svg", (svg + element + "</svg>").encode(), str(tmp_path))
    assert outcome.status == "input-error" and expect in outcome.detail, outcome
