"""A parametric unlined kimono (hitoe) pattern from the standard measurements (data/patterns/kimono/REFERENCE.md).

Construction (finished sizes, cm: the outlines are the sewing lines, no seam allowance)
------------------------------------------------------------------------------------
A kimono is cut from one bolt into straight rectangles. Seven pieces are made here:

- **migoro_right, migoro_left** (body panels 身頃): one strip each, `shoulder` wide (katahaba, from the centre back
  to the sleeve seam) and 2 x `length` long, running from the front hem up over the shoulder (the fold line
  y = length) and down to the back hem. Along the centre edge: the okumi seam on the front, then the neck: a
  diagonal from the okumi top (`okumi_drop` below the shoulder) up to the neck point on the shoulder line
  (`neck_width` from the centre, 衿肩あき), then a short line back to the centre `back_neck_drop` below the shoulder
  (繰越); then the back seam down to the back hem. Along the outer edge, from the front hem: side seam, underarm
  opening (身八つ口, `underarm_opening`), sleeve attachment (袖付け, `sleeve_attachment`) up to the shoulder fold,
  then the same three mirrored down the back.
- **okumi_right, okumi_left** (front overlap panels 衽): `okumi_width` wide, sewn along the migoro's front centre
  edge up to `okumi_drop` below the shoulder, where the okumi comes to a point (剣先); from there its top is cut on
  the slant down to its front edge at `collar_end` above the hem (衿先). The collar is sewn along that slant (衽の
  衿付け), which continues the body panel's neck diagonal almost straight (8° on the standard size): cut square,
  with the collar along the top and down the front edge, the straight collar had to turn a right angle at the
  okumi's corner, and on the body the under collar crumpled there, compressed by up to 47 %.
- **sode_right, sode_left** (sleeves 袖): **one piece each**, `sleeve_width` wide and 2 x `sleeve_depth` long,
  folded at the top (the sleeve crease 袖山 at y = sleeve_depth, in line with the shoulder fold), as it is cut.
  Seams: the sleeve attachment (front and back halves to the migoro), the bottom (袖底: the two short ends), the
  cuff side below the hand opening (袖口下, `sleeve_opening` left open from the crease down), and between those two
  the rounded corner (袖の丸み, `sleeve_round`, a quarter circle: 2 cm on a standard or formal kimono, up to ~12 cm
  on everyday ones). The body side below the attachment stays open (振り).
- **eri** (collar 衿): a strip `collar_width` wide whose one long edge is sewn, left collar end to right collar end,
  along the okumi's slanted top, the neck diagonal and the back neck of each side; its length is their sum.
The over-collar (tomoeri 共衿) is left out: it is a second layer on the front part of the collar and adds no shape.

The fronts: the wearer's left front goes over the right (left over right), so in the placement hint the left okumi
sits 1 cm in front of the right one, and `meta["layers"]` puts the left okumi, the left body panel's front and the
collar's left crossing part on layer 2 over their right counterparts on layer 1 (kept apart in the wrap).

Every seam joins two edges of equal length (outlines are split where a seam covers only part of an edge) and every
seam is `reversed` (all pieces face outwards). Edge names of every piece are in `pattern.meta["kimono"]["edges"]`.

Placement hints (metres, Y up, facing +Z, feet at y = 0): a T-shape as on a kimono stand around a standing body
of `body_height_m` (1.67 by default, the built-in body): body panels and sleeves hang from a fold over the shoulder
line (`Fold`, a half cylinder `body_depth_m` across, so front halves lie in the plane z = centre + depth / 2 and
back halves in z = centre - depth / 2); sleeves continue the shoulder line outwards with their crease on the same
fold, so the attachment seams meet exactly; okumi hang in front beside the centre front; the collar hangs over the
back of the neck, centred at the back, down the front and the back (a rough start; a wrap lays it along the
neckline). The wearer's right is -X.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, fields, replace

import numpy as np

from ..errors import InputError
from ._layers import LayerRegion
from ._types import Curve, EdgeRef, Fold, Pattern, Piece, Placement, Seam

#: Allowed ranges, cm (a child's kimono to a tall adult's; furisode sleeves reach ~115 cm).
RANGES = {
    "length": (60.0, 220.0),
    "yuki": (30.0, 95.0),
    "shoulder": (15.0, 45.0),
    "sleeve_depth": (20.0, 125.0),
    "bolt_width": (28.0, 48.0),
}
#: Seam allowance per side assumed when checking that a piece fits the bolt, cm.
SEAM_ALLOWANCE = 1.0


@dataclass(frozen=True)
class KimonoSize:
    """Kimono measurements, finished, cm. Defaults: the standard women's size (REFERENCE.md).

    The six principal measurements (the CLI options): length (身丈, shoulder to hem), yuki (裄, centre back to the
    sleeve end = shoulder + sleeve_width), shoulder (肩幅), sleeve_width (袖幅; None: yuki - shoulder), sleeve_depth
    (袖丈), bolt_width (反物 width; every piece must fit it with 1 cm seam allowances). The details below default
    to None: derived from those (values for the standard size in brackets).
    """

    length: float = 158.0
    yuki: float = 63.0
    shoulder: float = 31.0
    sleeve_width: float | None = None
    sleeve_depth: float = 49.0
    bolt_width: float = 37.0
    sleeve_attachment: float | None = None  # 袖付け: min(23, sleeve_depth - 6)  [23]
    underarm_opening: float | None = None  # 身八つ口: 0.09 x length  [14.2]
    sleeve_opening: float | None = None  # 袖口: min(23, sleeve_depth - 4)  [23]
    okumi_width: float | None = None  # 衽幅: bolt_width / 2 - 3.5  [15]
    okumi_drop: float | None = None  # 衽下がり, shoulder to okumi top: 23 x length / 158  [23]
    collar_end: float | None = None  # 衿下, hem to collar end: 0.48 x length  [75.8]
    collar_width: float = 5.5  # 衿幅
    neck_width: float = 9.0  # 衿肩あき, centre to the neck point on the shoulder
    back_neck_drop: float = 2.0  # 繰越
    sleeve_round: float = 2.0  # 袖の丸み, radius of the sleeve bag's rounded bottom corner at the cuff; 0: square

    def resolved(self) -> KimonoSize:
        """All derived values filled in, after checking every number; InputError names the bad option."""
        for f in fields(self):
            v = getattr(self, f.name)
            if v is not None and (isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v)):
                raise InputError(f"{_opt(f.name)} must be a finite number of centimetres, got {v!r}", _opt(f.name))
        for name, (lo, hi) in RANGES.items():
            v = getattr(self, name)
            if not lo <= v <= hi:
                raise InputError(f"{name.replace('_', ' ')} {v:g} cm is outside {lo:g}..{hi:g} cm", _opt(name))
        if self.yuki <= self.shoulder:
            raise InputError(
                f"yuki ({self.yuki:g} cm) must exceed the shoulder width ({self.shoulder:g} cm): yuki is "
                "the shoulder width plus the sleeve width",
                "--yuki",
            )
        sw = self.yuki - self.shoulder if self.sleeve_width is None else float(self.sleeve_width)
        if self.sleeve_width is not None and abs(self.shoulder + sw - self.yuki) > 0.5:
            raise InputError(
                f"yuki ({self.yuki:g}) must equal shoulder ({self.shoulder:g}) + sleeve width ({sw:g}) "
                "cm; give two of the three",
                "--sleeve-width",
            )
        usable = self.bolt_width - 2 * SEAM_ALLOWANCE
        for name, v in (("sleeve_width", sw), ("shoulder", self.shoulder)):
            if not 10.0 <= v <= usable:
                raise InputError(
                    f"{name.replace('_', ' ')} {v:g} cm does not fit the bolt width {self.bolt_width:g} "
                    f"cm (10..{usable:g} cm with {SEAM_ALLOWANCE:g} cm seam allowances)",
                    _opt(name),
                )
        d = self.sleeve_depth
        att = min(23.0, d - 6.0) if self.sleeve_attachment is None else self.sleeve_attachment
        hand = min(23.0, d - 4.0) if self.sleeve_opening is None else self.sleeve_opening
        under = 0.09 * self.length if self.underarm_opening is None else self.underarm_opening
        okw = self.bolt_width / 2 - 3.5 if self.okumi_width is None else self.okumi_width
        drop = 23.0 * self.length / 158.0 if self.okumi_drop is None else self.okumi_drop
        cend = 0.48 * self.length if self.collar_end is None else self.collar_end
        out = KimonoSize(
            self.length,
            self.yuki,
            self.shoulder,
            sw,
            d,
            self.bolt_width,
            att,
            under,
            hand,
            okw,
            drop,
            cend,
            self.collar_width,
            self.neck_width,
            self.back_neck_drop,
            self.sleeve_round,
        )
        checks = [
            (
                0 < att <= d - 3,
                "sleeve_attachment",
                f"must be positive and at least 3 cm short of the sleeve depth {d:g}",
            ),
            (
                0 < hand <= d - 3,
                "sleeve_opening",
                f"must be positive and at least 3 cm short of the sleeve depth {d:g}",
            ),
            (
                0 < under and att + under <= 0.6 * self.length,
                "underarm_opening",
                "with the sleeve attachment must stay within 60 % of the length",
            ),
            (4 <= okw <= self.bolt_width / 2, "okumi_width", f"must be 4..{self.bolt_width / 2:g} cm (half the bolt)"),
            (5 <= drop <= 0.4 * self.length, "okumi_drop", "must be 5 cm .. 40 % of the length"),
            (0 <= cend < self.length - drop - 5, "collar_end", "must leave at least 5 cm of collar on the okumi"),
            (2 <= self.collar_width <= self.bolt_width / 2, "collar_width", "must be 2 cm .. half the bolt width"),
            (2 <= self.neck_width <= self.shoulder - 5, "neck_width", "must be 2 cm .. the shoulder width - 5"),
            (0 <= self.back_neck_drop <= 8, "back_neck_drop", "must be 0..8 cm"),
            (
                0 <= self.sleeve_round <= min(15.0, sw / 2, d - hand - 1),
                "sleeve_round",
                f"must be 0..{min(15.0, sw / 2, d - hand - 1):g} cm (15 cm, half the sleeve width, and 1 cm short "
                "of the hand opening)",
            ),
        ]
        for ok, name, why in checks:
            if not ok:
                raise InputError(f"{name.replace('_', ' ')} {getattr(out, name):g} cm {why}", _opt(name))
        return out

    def label(self) -> str:
        """Short description, e.g. 'kimono 158/63/31/49' (length/yuki/shoulder/sleeve depth)."""
        return f"kimono {self.length:g}/{self.yuki:g}/{self.shoulder:g}/{self.sleeve_depth:g}"


#: Length (身丈) of a kimono worn without an ohashori fold, as a fraction of the wearer's height: from the shoulder
#: line (0.84 h) over the chest to just above the ankles. A standard kimono is longer (158 cm for 1.60-1.70 m) and
#: the excess is folded up under the obi (ohashori), a fold the wrap does not make: dressed as it is, its hem
#: would pile on the floor.
UNFOLDED_LENGTH_RATIO = 0.815


def fitted_size(body_height_m: float, size: KimonoSize | None = None) -> KimonoSize:
    """`size` (default: the standard size) with its length cut for `body_height_m` (metres) worn without an
    ohashori fold (UNFOLDED_LENGTH_RATIO), rounded to 0.5 cm."""
    if not (math.isfinite(body_height_m) and 0.5 <= body_height_m <= 2.5):
        raise InputError(f"body height {body_height_m!r} m is outside 0.5..2.5 m", "--fit-height")
    base = size or KimonoSize()
    return replace(base, length=round(2 * UNFOLDED_LENGTH_RATIO * body_height_m * 100) / 2)


def default_kimono() -> Pattern:
    """The kimono that `kitsuke demo` dresses and the packaged strokes `kimono_default` place: the standard size
    cut to the default body's height (1.666 m), worn without an ohashori fold (`fitted_size`)."""
    return make_kimono(fitted_size(DEFAULT_BODY_HEIGHT_M), body_height_m=DEFAULT_BODY_HEIGHT_M)


#: Height of `kitsuke.body.default_body()`, metres (checked by its tests).
DEFAULT_BODY_HEIGHT_M = 1.666


def _opt(name: str) -> str:
    return "--" + name.replace("_", "-")


def _piece(
    name: str, pts: list, edge_names: list[str], placement: Placement, curves: dict[str, Curve]
) -> tuple[Piece, dict[str, int]]:
    index = {n: i for i, n in enumerate(edge_names)}
    piece = Piece(name, np.array(pts, dtype=np.float64), {index[n]: c for n, c in curves.items()}, False, placement)
    return piece, index


def make_kimono(
    size: KimonoSize | None = None,
    *,
    body_height_m: float = 1.67,
    body_center_z_m: float = 0.03,
    body_depth_m: float = 0.34,
) -> Pattern:
    """The kimono pattern for `size` (default: the standard size) with its seams and placement hints.

    body_height_m, body_center_z_m, body_depth_m : the standing body the placement hints are made for (feet at
        y = 0, facing +Z): its height, the z of its torso's centre and the front-to-back depth the fold wraps.
    """
    s = (size or KimonoSize()).resolved()
    L, K, W, D = s.length, s.shoulder, s.sleeve_width, s.sleeve_depth
    a, u, c = s.sleeve_attachment, s.underarm_opening, s.sleeve_opening
    n, k, sd, O, H = s.neck_width, s.back_neck_drop, s.okumi_drop, s.okumi_width, s.length - s.okumi_drop
    E = s.collar_end
    # Placement: the shoulder line (top of the fold) at 0.84 body height; the fold's half-cylinder spans the depth.
    r = 50.0 * body_depth_m  # fold radius, cm
    shoulder_y = 0.84 * body_height_m
    zf = body_center_z_m + body_depth_m / 2  # front plane, m
    # With the fold, the fold line y_f ends up at local height y_f - (pi/2 - 1) r: lift by that much.
    lift = (math.pi / 2 - 1) * r / 100.0

    def hang(x_m: float, fold_y_cm: float, z_m: float = zf, fold: bool = True) -> Placement:
        y0 = shoulder_y - fold_y_cm / 100.0 + (lift if fold else 0.0)
        return Placement([x_m, y0, z_m], [0, 0, 0], Fold(fold_y_cm, 2 * r) if fold else None)

    pieces, edges = [], {}

    def add(name, pts, names, placement, curves=None):
        piece, e = _piece(name, pts, names, placement, curves or {})
        pieces.append(piece)
        edges[name] = e

    # Right body panel: side at x = 0 (world x = -K), centre at x = K (world 0).
    add(
        "migoro_right",
        [
            (0, 0),
            (K, 0),
            (K, L - sd),
            (K - n, L),
            (K, L + k),
            (K, 2 * L),
            (0, 2 * L),
            (0, L + a + u),
            (0, L + a),
            (0, L),
            (0, L - a),
            (0, L - a - u),
        ],
        [
            "front_hem",
            "front_centre",
            "front_neck",
            "back_neck",
            "back_centre",
            "back_hem",
            "back_side",
            "back_underarm",
            "back_sleeve",
            "front_sleeve",
            "front_underarm",
            "front_side",
        ],
        hang(-K / 100.0, L),
    )
    add(
        "migoro_left",
        [
            (0, 0),
            (K, 0),
            (K, L - a - u),
            (K, L - a),
            (K, L),
            (K, L + a),
            (K, L + a + u),
            (K, 2 * L),
            (0, 2 * L),
            (0, L + k),
            (n, L),
            (0, L - sd),
        ],
        [
            "front_hem",
            "front_side",
            "front_underarm",
            "front_sleeve",
            "back_sleeve",
            "back_underarm",
            "back_side",
            "back_hem",
            "back_centre",
            "back_neck",
            "front_neck",
            "front_centre",
        ],
        hang(0.0, L),
    )
    # Okumi: the right one lies over the left body panel's front (under the left okumi), 1 cm behind it.
    # The centre edge (sewn to the migoro) runs up to the point (剣先) at H; the front edge up to the collar end at E;
    # the collar is sewn along the slant between them.
    add(
        "okumi_right",
        [(0, 0), (O, 0), (O, E), (0, H)],
        ["hem", "front_free", "front_collar", "centre"],
        Placement([0.0, shoulder_y + lift - L / 100.0, zf + 0.005], [0, 0, 0]),
    )
    add(
        "okumi_left",
        [(0, 0), (O, 0), (O, H), (0, E)],
        ["hem", "centre", "front_collar", "front_free"],
        Placement([-O / 100.0, shoulder_y + lift - L / 100.0, zf + 0.015], [0, 0, 0]),
    )
    # Sleeves: one folded piece each, crease at y = D on the shoulder fold; body side towards the body panel. The
    # cuff side's two bottom corners (front and back half of the bag's corner) are rounded by R: a quarter circle
    # that bulges out of the piece ("circle" curve: sagitta / chord = (1 - cos 45°) / (2 sin 45°)).
    R = s.sleeve_round
    arc = Curve("circle", [[0.5, -(1 - math.sqrt(0.5)) / (2 * math.sqrt(0.5))]])
    right = [
        ((0, 0), "front_bottom"),
        ((W, 0), "front_furi"),
        ((W, D - a), "front_attach"),
        ((W, D), "back_attach"),
        ((W, D + a), "back_furi"),
        ((W, 2 * D), "back_bottom"),
        ((0, 2 * D), "back_cuff_seam"),
        ((0, D + c), "back_opening"),
        ((0, D), "front_opening"),
        ((0, D - c), "front_cuff_seam"),
    ]
    left = [
        ((0, 0), "front_bottom"),
        ((W, 0), "front_cuff_seam"),
        ((W, D - c), "front_opening"),
        ((W, D), "back_opening"),
        ((W, D + c), "back_cuff_seam"),
        ((W, 2 * D), "back_bottom"),
        ((0, 2 * D), "back_furi"),
        ((0, D + a), "back_attach"),
        ((0, D), "front_attach"),
        ((0, D - a), "front_furi"),
    ]
    if R > 0:
        # Each square corner becomes an arc edge between two points R from it along its two edges. The later
        # index of a list is spliced first, so the earlier one still names the original point.
        right[0:1] = [((R, 0), "front_bottom")]
        right[6:7] = [((R, 2 * D), "back_round"), ((0, 2 * D - R), "back_cuff_seam")]
        right.append(((0, R), "front_round"))
        left[5:6] = [((W, 2 * D - R), "back_round"), ((W - R, 2 * D), "back_bottom")]
        left[1:2] = [((W - R, 0), "front_round"), ((W, R), "front_cuff_seam")]
    for side, outline, x0 in (("right", right, -(K + W)), ("left", left, K)):
        rounds = {"front_round": arc, "back_round": arc} if R > 0 else {}
        add(f"sode_{side}", [p for p, _ in outline], [nm for _, nm in outline], hang(x0 / 100.0, D), rounds)
    # Collar: its bottom edge (y = 0), left collar end (x = 0) to right collar end, is sewn segment by segment.
    diag, bneck, slant = math.hypot(n, sd), math.hypot(n, k), math.hypot(O, H - E)
    segs = [
        ("left_okumi", slant),
        ("left_front_neck", diag),
        ("left_back_neck", bneck),
        ("right_back_neck", bneck),
        ("right_front_neck", diag),
        ("right_okumi", slant),
    ]
    xs = np.concatenate([[0.0], np.cumsum([v for _, v in segs])])
    Lc, e = float(xs[-1]), s.collar_width
    # Upright strip: the sewn side is x = e, walked upwards from the left collar end (y = 0) to the right one.
    collar_pts = [(e, float(y)) for y in xs[:-1]] + [(e, Lc), (0.0, Lc), (0.0, 0.0)]
    collar_names = [nm for nm, _ in segs] + ["right_end", "outer", "left_end"]
    # Hint (rough): folded at its middle over the back of the neck, the left half down the left okumi's front
    # edge (its sewn side on that edge), the right half down the centre back.
    add(
        "eri",
        collar_pts,
        collar_names,
        Placement(
            [-(O + e) / 100.0, shoulder_y + lift + 0.01 - Lc / 200.0, zf + 0.025], [0, 0, 0], Fold(Lc / 2, 2 * r + 5.0)
        ),
    )

    def seam(pa, ea, pb, eb):
        return Seam(EdgeRef(pa, edges[pa][ea]), EdgeRef(pb, edges[pb][eb]), True)

    seams = [
        seam("migoro_right", "back_centre", "migoro_left", "back_centre"),
        seam("migoro_right", "front_side", "migoro_right", "back_side"),
        seam("migoro_left", "front_side", "migoro_left", "back_side"),
        seam("okumi_right", "centre", "migoro_right", "front_centre"),
        seam("okumi_left", "centre", "migoro_left", "front_centre"),
    ]
    for side in ("right", "left"):
        sode, mig = f"sode_{side}", f"migoro_{side}"
        seams += [
            seam(sode, "front_attach", mig, "front_sleeve"),
            seam(sode, "back_attach", mig, "back_sleeve"),
            seam(sode, "front_bottom", sode, "back_bottom"),
            seam(sode, "front_cuff_seam", sode, "back_cuff_seam"),
        ]
        if R > 0:
            seams.append(seam(sode, "front_round", sode, "back_round"))
    for side in ("left", "right"):
        seams += [
            seam("eri", f"{side}_okumi", f"okumi_{side}", "front_collar"),
            seam("eri", f"{side}_front_neck", f"migoro_{side}", "front_neck"),
            seam("eri", f"{side}_back_neck", f"migoro_{side}", "back_neck"),
        ]
    # Left over right (SPEC §5.4): the left okumi, the left body panel's front and the collar down the left okumi
    # lie over their right counterparts where they cross on the body.
    front = (0.0, 0.0, K, L)
    crossing = slant  # the collar along an okumi's slanted top
    layers = [
        LayerRegion("okumi_left", 2),
        LayerRegion("migoro_left", 2, front),
        LayerRegion("eri", 2, (0.0, 0.0, e, crossing)),
        LayerRegion("okumi_right", 1),
        LayerRegion("migoro_right", 1, front),
        LayerRegion("eri", 1, (0.0, Lc - crossing, e, Lc)),
    ]
    meta = {
        "kimono": {"size": asdict(s), "label": s.label(), "edges": edges},
        "layers": [r.to_dict() for r in layers],
    }
    return Pattern("kimono", pieces, seams, meta)
