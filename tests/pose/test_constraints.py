"""Constraint tables (SPEC §3.4, §5.2): interpolation, file round trip, validation, the shipped estimate."""

from __future__ import annotations

import json
import math
from importlib import resources

import numpy as np
import pytest

from kitsuke.errors import InputError
from kitsuke.pose import (
    ConstraintTable,
    KimonoLegGeometry,
    PairLimit,
    default_constraints,
    geometric_estimate,
    packaged_constraints,
    read_constraints,
    write_constraints,
    write_default_constraints,
)
from kitsuke.pose._constraints import ellipse_perimeter


def test_interpolation_is_linear_and_periodic_over_180_degrees():
    lim = PairLimit(theta_deg=np.array([0.0, 60.0, 120.0]), max_distance_m=np.array([0.3, 0.2, 0.25]), area_m2=0.05)
    e = lambda deg: float(lim.max_distance(math.radians(deg)))  # noqa: E731
    assert e(0) == pytest.approx(0.3) and e(60) == pytest.approx(0.2) and e(30) == pytest.approx(0.25)
    assert e(90) == pytest.approx(0.225)
    assert e(150) == pytest.approx(0.275)  # between 120° (0.25) and 180° ≡ 0° (0.3)
    assert e(180) == pytest.approx(0.3) and e(-30) == pytest.approx(e(150)) and e(390) == pytest.approx(e(30))


def test_round_trip_and_corrected_file_form(tmp_path):
    t = geometric_estimate()
    p = write_constraints(t, tmp_path / "t.json")
    back = read_constraints(p)
    for name in ("knee", "ankle"):
        a, b = back.pair(name), t.pair(name)
        assert np.array_equal(a.theta_deg, b.theta_deg) and np.array_equal(a.max_distance_m, b.max_distance_m)
        assert a.area_m2 == b.area_m2
    assert (back.source, back.garment) == (t.source, t.garment)
    (tmp_path / "wrapped.json").write_text(json.dumps({"constraints": t.to_json()}))
    assert read_constraints(tmp_path / "wrapped.json").source == "geometric estimate"


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (lambda d: d.pop("ankle"), "missing the 'ankle' table"),
        (lambda d: d["knee"].update(theta_deg=[0, 30, 20], max_distance_m=[0.3, 0.3, 0.3]), "strictly increasing"),
        (lambda d: d["knee"].update(theta_deg=[0, 90, 180], max_distance_m=[0.3, 0.3, 0.3]), "within [0, 180)"),
        (lambda d: d["knee"]["max_distance_m"].__setitem__(0, -1), "positive"),
        (lambda d: d["knee"].__setitem__("max_distance_m", [0.3]), "same length"),
        (lambda d: d["ankle"].__setitem__("area_m2", 0), "area_m2 must be positive"),
    ],
)
def test_bad_tables_raise_input_error(tmp_path, edit, message):
    doc = geometric_estimate().to_json()
    edit(doc)
    (tmp_path / "bad.json").write_text(json.dumps(doc))
    with pytest.raises(InputError, match=message.replace("[", r"\[").replace("(", r"\(").replace(")", r"\)")):
        read_constraints(tmp_path / "bad.json")


def test_bad_table_via_cli(tmp_path, run_cli):
    from .conftest import KICK

    (tmp_path / "bad.json").write_text(json.dumps({"knee": {}}))
    r = run_cli("pose", "correct", KICK, "-o", tmp_path / "o.json", "--constraints", tmp_path / "bad.json")
    assert r.code == 2 and "bad.json" in r.err and r.err.count("\n") == 1
    assert not (tmp_path / "o.json").exists()


def test_shipped_table_is_the_regenerated_geometric_estimate(tmp_path):
    shipped = resources.files("kitsuke") / "assets" / "constraints" / "kimono_standard_geometric.json"
    regenerated = write_default_constraints(tmp_path / "regen.json")
    assert json.loads(shipped.read_text()) == json.loads(regenerated.read_text())
    t = packaged_constraints("geometric")
    assert t.source == "geometric estimate" and "158" in t.garment
    assert list(t.knee.theta_deg) == list(range(0, 180, 15))
    default = default_constraints()  # the correction's default: the table calibrated by simulation
    assert default.source == "calibrated" and list(default.knee.theta_deg) == list(range(0, 180, 15))


def test_geometric_estimate_numbers():
    """The derivation in `geometric_estimate`'s docstring, checked by hand."""
    g = KimonoLegGeometry()
    assert g.circumference_cm == 136.0
    t = geometric_estimate(g)
    # knee: rest tube perimeter 136 - 38 = 98 cm, ellipse with b = 0.75 a
    a = 98.0 / ellipse_perimeter(1.0, 0.75)
    assert t.knee.area_m2 == pytest.approx(math.pi * a * 0.75 * a / 1e4, abs=1e-6)
    s = 121.0 / 98.0
    assert t.knee.max_distance_m[0] == pytest.approx((2 * s * a - 12.0) / 100, abs=1e-6)  # θ = 0: across
    assert t.knee.max_distance_m[6] == pytest.approx((2 * s * 0.75 * a - 12.0) / 100, abs=1e-6)  # 90°: front-back
    assert 0.30 < t.knee.max_distance_m[0] < 0.33 and 0.19 < t.knee.max_distance_m[6] < 0.22
    # symmetric in θ ↔ 180° − θ, and the widest across the body
    e = t.knee.max_distance_m
    assert np.allclose(e[1:], e[1:][::-1]) and e.argmax() == 0
    assert (t.ankle.max_distance_m > t.knee.max_distance_m).all()  # thinner legs: more room at the ankle


def test_perimeter_formula():
    assert ellipse_perimeter(1.0, 1.0) == pytest.approx(2 * math.pi)
    # a flat ellipse tends to 4a
    assert ellipse_perimeter(1.0, 1e-9) == pytest.approx(4.0, rel=1e-3)


def test_table_object_validation():
    with pytest.raises(ValueError):
        PairLimit(theta_deg=np.array([]), max_distance_m=np.array([]), area_m2=1.0)
    with pytest.raises(ValueError, match="unknown joint pair"):
        default_constraints().pair("elbow")
    assert isinstance(default_constraints(), ConstraintTable)
