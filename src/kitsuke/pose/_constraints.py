"""Kimono constraint tables (SPEC §3.4 `constraints`, §5.2): E_J(θ) and the cross-section area A_J per joint pair.

E_J(θ) is the largest horizontal distance between the two joints of a pair (knees, ankles) that the kimono allows
when the line between them makes the angle θ with the body's left→right hip axis; A_J is the area of the kimono's
cross-section near those joints (SPEC §5.2). kitsuke ships two tables for the standard kimono: the default, a
*geometric estimate* (`geometric_estimate`, derivation in its docstring), and one calibrated by cloth simulation
(`kitsuke kimono calibrate`, `kitsuke.tryon.calibrate`), by name "calibrated".
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

from .._files import read_json, write_json_atomic
from ..errors import InputError

#: Joint pairs the correction handles, in the order it handles them (SPEC §5.3: knees first, then ankles).
PAIRS: tuple[str, ...] = ("knee", "ankle")

#: The tables shipped for the standard kimono, by name: "calibrated" (cloth simulation, `kitsuke kimono
#: calibrate`; the default) and "geometric" (`geometric_estimate`).
PACKAGED_CONSTRAINTS = {
    "geometric": "kimono_standard_geometric.json",
    "calibrated": "kimono_standard_calibrated.json",
}
#: The shipped table the correction uses unless told otherwise.
DEFAULT_CONSTRAINTS = "calibrated"


@dataclass(frozen=True)
class PairLimit:
    """The limit for one joint pair.

    Attributes
    ----------
    theta_deg : (m,) float64, degrees, strictly increasing in [0, 180): angles of the horizontal line between the
        two joints against the left→right hip axis.
    max_distance_m : (m,) float64, metres, > 0: E(θ) at those angles.
    area_m2 : float, square metres: area A of the kimono's cross-section near the joints (ellipse K, SPEC §5.3).
    """

    theta_deg: np.ndarray
    max_distance_m: np.ndarray
    area_m2: float

    def __post_init__(self) -> None:
        t = np.asarray(self.theta_deg, dtype=np.float64).reshape(-1)
        e = np.asarray(self.max_distance_m, dtype=np.float64).reshape(-1)
        if len(t) == 0 or len(t) != len(e):
            raise ValueError("theta_deg and max_distance_m must be non-empty and of the same length")
        if not (np.isfinite(t).all() and np.isfinite(e).all()):
            raise ValueError("theta_deg and max_distance_m must be finite")
        if t[0] < 0 or t[-1] >= 180 or (np.diff(t) <= 0).any():
            raise ValueError("theta_deg must be strictly increasing within [0, 180)")
        if (e <= 0).any():
            raise ValueError("max_distance_m must be positive")
        if not (math.isfinite(self.area_m2) and self.area_m2 > 0):
            raise ValueError("area_m2 must be positive")
        object.__setattr__(self, "theta_deg", t)
        object.__setattr__(self, "max_distance_m", e)

    def periodic_table(self) -> tuple[np.ndarray, np.ndarray]:
        """(m+2,) radians and (m+2,) metres: the table wrapped once on each side, for linear interpolation
        that is periodic over 180° (the entries before 0° and after the last angle come from the other end)."""
        t = np.deg2rad(self.theta_deg)
        e = self.max_distance_m
        tt = np.concatenate([[t[-1] - math.pi], t, [t[0] + math.pi]])
        ee = np.concatenate([[e[-1]], e, [e[0]]])
        return tt, ee

    def max_distance(self, theta_rad: np.ndarray | float) -> np.ndarray:
        """E(θ), metres, linear between table entries and periodic over 180° (θ in radians, any range)."""
        tt, ee = self.periodic_table()
        th = np.mod(np.asarray(theta_rad, dtype=np.float64), math.pi)
        return np.interp(th, tt, ee)

    def to_json(self) -> dict[str, Any]:
        return {
            "theta_deg": [round(float(x), 6) for x in self.theta_deg],
            "max_distance_m": [round(float(x), 6) for x in self.max_distance_m],
            "area_m2": round(float(self.area_m2), 6),
        }


@dataclass(frozen=True)
class ConstraintTable:
    """E and A for the knees and the ankles, with where they came from (SPEC §3.4).

    Attributes
    ----------
    knee, ankle : the per-pair limits.
    source : "calibrated" (cloth simulation) or "geometric estimate".
    garment : a label of the garment the table is for, e.g. "kimono 158/63/32/31".
    """

    knee: PairLimit
    ankle: PairLimit
    source: str = "geometric estimate"
    garment: str = "kimono"

    def pair(self, name: str) -> PairLimit:
        if name not in PAIRS:
            raise ValueError(f"unknown joint pair {name!r}; pairs are {PAIRS}")
        return self.knee if name == "knee" else self.ankle

    def to_json(self) -> dict[str, Any]:
        return {
            "source": self.source,
            "garment": self.garment,
            "knee": self.knee.to_json(),
            "ankle": self.ankle.to_json(),
        }

    @classmethod
    def from_json(cls, doc: Any, path: str | os.PathLike[str] = "<constraints>") -> ConstraintTable:
        """Validate a `constraints` object (SPEC §3.4); InputError naming `path` and what is wrong."""
        p = Path(path)
        if not isinstance(doc, dict):
            raise InputError("constraints must be an object with knee and ankle tables", p)
        source = doc.get("source", "geometric estimate")
        garment = doc.get("garment", "kimono")
        if not isinstance(source, str) or not isinstance(garment, str):
            raise InputError("constraints: source and garment must be strings", p)
        limits = {}
        for name in PAIRS:
            d = doc.get(name)
            if not isinstance(d, dict):
                raise InputError(f"constraints: missing the {name!r} table", p)
            try:
                limits[name] = PairLimit(
                    theta_deg=np.array(d.get("theta_deg"), dtype=np.float64),
                    max_distance_m=np.array(d.get("max_distance_m"), dtype=np.float64),
                    area_m2=float(d.get("area_m2")),
                )
            except (TypeError, ValueError) as e:
                raise InputError(f"constraints: bad {name!r} table: {e}", p) from None
        return cls(knee=limits["knee"], ankle=limits["ankle"], source=source, garment=garment)


def read_constraints(path: str | os.PathLike[str]) -> ConstraintTable:
    """Read a constraints table: a file holding the SPEC §3.4 `constraints` object, either alone or as the
    `constraints` member of a corrected poses file."""
    doc = read_json(path, what="constraints file")
    if isinstance(doc, dict) and "constraints" in doc and "knee" not in doc:
        doc = doc["constraints"]
    return ConstraintTable.from_json(doc, path)


def write_constraints(table: ConstraintTable, path: str | os.PathLike[str]) -> Path:
    """Write a constraints table as JSON (the SPEC §3.4 `constraints` object), atomically."""
    return write_json_atomic(path, table.to_json())


def default_constraints() -> ConstraintTable:
    """The table kitsuke corrects with by default: the standard kimono's, calibrated by cloth simulation
    (`kitsuke kimono calibrate`, SPEC §5.2). The geometric estimate is `packaged_constraints("geometric")`."""
    return packaged_constraints(DEFAULT_CONSTRAINTS)


def packaged_constraints(name: str) -> ConstraintTable:
    """A table shipped with kitsuke, by name (`PACKAGED_CONSTRAINTS`: "calibrated" or "geometric")."""
    if name not in PACKAGED_CONSTRAINTS:
        raise InputError(f"no shipped constraints table {name!r}; shipped: {', '.join(PACKAGED_CONSTRAINTS)}")
    ref = resources.files("kitsuke") / "assets" / "constraints" / PACKAGED_CONSTRAINTS[name]
    with resources.as_file(ref) as p:
        return read_constraints(p)


def load_constraints(name_or_path: str | os.PathLike[str]) -> ConstraintTable:
    """A shipped table by name ("calibrated", "geometric") or a table file (`read_constraints`)."""
    if str(name_or_path) in PACKAGED_CONSTRAINTS:
        return packaged_constraints(str(name_or_path))
    return read_constraints(name_or_path)


# ------------------------------------------------------------------------------------------ geometric estimate


@dataclass(frozen=True)
class KimonoLegGeometry:
    """What the geometric estimate needs to know about a kimono and the legs inside it (centimetres).

    The defaults are the standard finished size (data/patterns/kimono/REFERENCE.md: length 158, yuki 63, sleeve
    width 32, shoulder width 31, bolt about 36–38 cm wide) with the usual hem widths of a kimono cut from a
    37 cm bolt: back width 30 cm (about the shoulder width 31 less the back-seam curve), front width 23 cm (the
    rest of the body panel's width is folded inside as seam allowance) and okumi 15 cm (half a bolt less
    allowances).
    """

    length_cm: float = 158.0
    yuki_cm: float = 63.0
    sleeve_width_cm: float = 32.0
    shoulder_width_cm: float = 31.0
    bolt_width_cm: float = 37.0
    back_width_cm: float = 30.0
    front_width_cm: float = 23.0
    okumi_width_cm: float = 15.0
    #: Overlap of the left front over the right one as worn, at knee and at ankle height: the upper front
    #: covers the under front's front panel and okumi (front + okumi) at the knee, and the hem is wrapped a
    #: little tighter (suso-tsubomari, +6 cm) at the ankle.
    overlap_knee_cm: float = 38.0
    overlap_ankle_cm: float = 44.0
    #: The least overlap before the kimono "breaks" (the leg shows through the front opening): the upper front
    #: must still cover the under front's okumi.
    min_overlap_cm: float = 15.0
    #: Depth / width of the worn tube's cross-section (the lower body's depth over its width).
    depth_ratio: float = 0.75
    #: Radius of the leg's cross-section at the joint (knee girth about 38 cm, ankle about 22 cm).
    knee_radius_cm: float = 6.0
    ankle_radius_cm: float = 3.5

    @property
    def circumference_cm(self) -> float:
        """Cloth around the lower body: two backs, two fronts, two okumi."""
        return 2.0 * (self.back_width_cm + self.front_width_cm + self.okumi_width_cm)

    def label(self) -> str:
        return (
            f"kimono {self.length_cm:g}/{self.yuki_cm:g}/{self.sleeve_width_cm:g}/{self.shoulder_width_cm:g} "
            f"(length/yuki/sleeve width/shoulder width cm, bolt {self.bolt_width_cm:g} cm)"
        )


def ellipse_perimeter(a: float, b: float) -> float:
    """Perimeter of an ellipse with semi-axes a, b (Ramanujan's second approximation, error < 1e-9 relative for
    b/a ≥ 0.5)."""
    h = ((a - b) / (a + b)) ** 2
    return math.pi * (a + b) * (1.0 + 3.0 * h / (10.0 + math.sqrt(4.0 - 3.0 * h)))


def _semi_axes_for_perimeter(perimeter: float, ratio: float) -> tuple[float, float]:
    """Semi-axes (a, b = ratio·a) of the ellipse with the given perimeter."""
    a = perimeter / ellipse_perimeter(1.0, ratio)
    return a, ratio * a


def geometric_estimate(geometry: KimonoLegGeometry | None = None, *, step_deg: float = 15.0) -> ConstraintTable:
    """The provisional constraint table, from the kimono's geometry alone (no cloth simulation).

    Derivation, at the height of a joint pair J (knee or ankle), all lengths in cm:

    1. Cloth around the legs: the panels are straight, so at any height below the obi the cloth measures
       C = 2·(back width + front width + okumi width) = 2·(30 + 23 + 15) = 136.
    2. As worn, the left front overlaps the right one by o_J (38 at the knee, 44 at the ankle, where the hem is
       wrapped tighter), so the tube around the legs has perimeter P_J = C − o_J (98 and 92). Its cross-section is
       taken as an ellipse of depth/width ratio 0.75 with that perimeter: semi-axes (a_J, b_J) across and
       front-to-back. **A_J = π·a_J·b_J** is the kimono's initial cross-section area (SPEC §5.2 K).
    3. Separating the legs opens the overlap; the kimono breaks (the leg shows through the front) when less than
       the okumi width o_min = 15 remains. The most the tube can open is to perimeter P_open = C − o_min = 121.
       The obi holds the tube's shape at the waist, so the opened tube is taken as the rest ellipse scaled by
       s_J = P_open / P_J.
    4. Both legs (cross-section radius r_J: 6 at the knee, 3.5 at the ankle) must stay inside the opened tube,
       so the joint centres can be at most **E_J(θ) = 2·s_J·ρ_J(θ) − 2·r_J** apart along the direction θ, with
       ρ_J(θ) = a_J·b_J / sqrt((b_J cos θ)² + (a_J sin θ)²) the rest ellipse's radius in that direction (θ from
       the left→right hip axis, 90° = front-to-back).

    With the defaults: knee E(0°) = 31.8 cm, E(90°) = 20.8 cm, A = 0.0741 m²; ankle E(0°) = 36.8 cm,
    E(90°) = 25.8 cm, A = 0.0653 m². Wide side steps and long strides are limited, standing and small steps are
    not. Replace with a calibrated table (cloth simulation, SPEC §5.2) when one exists.
    """
    g = geometry or KimonoLegGeometry()
    if not (0 < step_deg <= 90) or abs(180.0 / step_deg - round(180.0 / step_deg)) > 1e-9:
        raise ValueError(f"step_deg must divide 180, got {step_deg}")
    theta_deg = np.arange(0.0, 180.0 - 1e-9, step_deg)
    th = np.deg2rad(theta_deg)
    c = g.circumference_cm
    p_open = c - g.min_overlap_cm
    limits = {}
    for name, overlap, radius in (
        ("knee", g.overlap_knee_cm, g.knee_radius_cm),
        ("ankle", g.overlap_ankle_cm, g.ankle_radius_cm),
    ):
        p_rest = c - overlap
        if not (0 < p_rest < p_open):
            raise ValueError(f"{name}: overlap {overlap} cm must be between {g.min_overlap_cm} and {c} cm")
        a, b = _semi_axes_for_perimeter(p_rest, g.depth_ratio)
        s = p_open / p_rest
        rho = a * b / np.sqrt((b * np.cos(th)) ** 2 + (a * np.sin(th)) ** 2)
        e_cm = 2.0 * s * rho - 2.0 * radius
        limits[name] = PairLimit(
            theta_deg=theta_deg,
            max_distance_m=np.round(e_cm / 100.0, 6),
            area_m2=round(math.pi * a * b / 1e4, 6),
        )
    return ConstraintTable(knee=limits["knee"], ankle=limits["ankle"], source="geometric estimate", garment=g.label())


def write_default_constraints(path: str | os.PathLike[str]) -> Path:
    """Regenerate the shipped table file (src/kitsuke/assets/constraints/) from `geometric_estimate()`.

    `python -c "from kitsuke.pose import write_default_constraints as w; w('src/kitsuke/assets/constraints/`
    `kimono_standard_geometric.json')"`; a test checks that the shipped file equals the regenerated one.
    """
    table = geometric_estimate()
    doc = table.to_json()
    doc["derivation"] = (
        "geometric estimate from the standard kimono's hem widths and overlap; see "
        "kitsuke.pose.geometric_estimate. The default table is calibrated by cloth simulation "
        "(kimono_standard_calibrated.json, `kitsuke kimono calibrate`)."
    )
    return write_json_atomic(path, doc)
