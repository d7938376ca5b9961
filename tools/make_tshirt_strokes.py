"""Generate the FreeSewing Teagan T-shirt (size cisMaleAdult42) sewn, and its strokes on the default body.

Run from the repository root: python tools/make_tshirt_strokes.py [OUT.json]

1. The pattern. `load_pattern` reads tests/data/pattern/teagan_tshirt_cisMaleAdult42.svg as three pieces and no
   seams: "front" and "back" are half pieces (FreeSewing: cut 1 on the fold; the fold is edge 6, x = 0), "sleeve"
   is one sleeve (cut 2, mirrored), and an SVG carries no stitching. `sewn_teagan()` makes the T-shirt from them
   with the public Pattern API and writes it to tests/data/pattern/teagan_tshirt_cisMaleAdult42_sewn.json:
   - front and back unfolded into whole pieces (the drawn half at x >= 0, its mirror image at x <= 0, the two hem
     halves joined into one edge). Seen from outside, the front's drawn half is the wearer's left, the back's the
     wearer's right;
   - the sleeve as drawn is the right sleeve (its x > 0 side, FreeSewing's single notch, is the front of the
     wearer's right arm when the sleeve's outer face looks up and its cap points at the body); its mirror image,
     moved back to x >= 0, is the left sleeve;
   - armholes and sleeve caps cut where the other side has a corner, matched by arc length along the seam from
     the front underarm over the shoulder to the back underarm (the cap is 58.61 cm, the armhole 58.57 cm: the
     ease is spread evenly), because a kitsuke seam joins two whole edges; corners closer than MERGE_CM are taken
     as one (the back's underarm corners are 0.02 cm apart; the front's 0.5 cm, which leaves a 0.52 cm part);
   - seams: side seams, shoulder seams, each sleeve's underarm seam, each sleeve cap to its armhole (front and
     back parts); the neckline, the hem and the sleeve hems stay open.
2. The strokes (drawn points on the default body, each pattern stroke as long as its body stroke), wearer's right
   first, per side:
   - front and back: a vertical line through the shoulder seam 1.7 cm out from the neck point (|u| = 15 cm), from
     1.5 cm below the seam, on the body in the plane |x| = FRONT_X (BACK_X) from 1.5 cm past the shoulder ridge
     down the front (back) to where the chest (shoulder blade) stands out most, not below CHEST_Y. The back's
     plane lies 2 cm further out, where the back's surface is about as wide as the pattern: in the front's plane
     the 3.5 cm or so of spare cloth each side gathers into a pleat down the centre back;
   - sleeve: two vertical lines on the sleeve, 2 cm to the front and to the back of the cap point sewn to the
     shoulder seam's end, from 1.5 cm below the cap to 1.5 cm short of the hem, on the body along the line on top
     of the shoulder and the arm moved 2 cm over the surface to the front (back), starting 1.5 cm (plus the
     cap's drop there) past where the shoulder seam ends (the seam measured on along the top line from the front
     stroke).
   The same rules as the GarmentCode shirt's (tools/make_shirt_strokes.py). The T-shirt is cut for a 110.5 cm
   chest and the default body's is about 84 cm, so it hangs loose: its 26.7 cm wide neckline lies on the flat tops
   of the shoulders and its 11 cm shoulder seams end on the upper arms.
"""

from __future__ import annotations

import sys
from dataclasses import dataclass, replace
from math import comb
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from _strokes_common import Slicer, cut, pair, pattern_top, sewn_point, smooth, torso_pair, write_strokes_file

from kitsuke.body import default_body
from kitsuke.dressing import arc_length
from kitsuke.pattern import Curve, EdgeRef, Pattern, Piece, Seam, load_pattern, save_pattern, validate

SVG = "tests/data/pattern/teagan_tshirt_cisMaleAdult42.svg"
SEWN = "tests/data/pattern/teagan_tshirt_cisMaleAdult42_sewn.json"
MERGE_CM = 0.3  # corners of the armhole and the cap closer than this (along the seam) are taken as one
SEAM_TOLERANCE = 0.01  # a seam's two edges may differ by this fraction of the longer one

TORSO_U = 15.0  # cm from the centre line: 1.7 cm out from the neck point along the shoulder seam (u 13.3 .. 24.1)
FRONT_X = 0.12  # m, the front strokes' plane |x|: down the chest (at 0.14 m the path runs off it at 1.33 m)
BACK_X = 0.14  # m, the back strokes' plane |x|: the back's surface there is about as wide as the pattern's 15 cm
TOP_GAP = 1.5  # cm between a torso stroke's start and the shoulder seam (and, on the body, the ridge)
SHOULDER_Y = 1.39  # m, about the default body's shoulder ridge height (picks the body section)
CHEST_Y = 1.26  # m, torso strokes stop above this height
SLEEVE_OFFSET = 2.0  # cm, the sleeve strokes lie this far to the front and the back of the sleeve's middle line
END_GAP = 1.5  # cm, sleeve strokes keep this far from the cap and the hem
ARM_END_X = 0.42  # m, |x| where the top line along the arm stops (the wrist is at 0.43 m)

# -- the pattern --------------------------------------------------------------------------------------------------


@dataclass
class Edge:
    """One outline edge while the pieces are rebuilt: absolute control points (cm), so that mirroring, reversing
    and cutting are plain point arithmetic. `kind` is None (straight), "quadratic" or "cubic"."""

    start: np.ndarray
    end: np.ndarray
    kind: str | None
    ctrl: np.ndarray  # (k, 2), empty for a straight edge
    label: str

    def points(self, t: np.ndarray) -> np.ndarray:
        """(len(t), 2) points at curve parameters t (Bernstein form of the Bézier)."""
        q = np.vstack([self.start, self.ctrl, self.end])
        k = len(q) - 1
        t = np.asarray(t, float)[:, None]
        return sum(comb(k, j) * (1 - t) ** (k - j) * t**j * q[j] for j in range(k + 1))

    def arc(self, n: int = 4001) -> tuple[np.ndarray, np.ndarray]:
        """Curve parameters (n,) and the arc length (n,) cm from the start at each."""
        t = np.linspace(0.0, 1.0, n)
        return t, arc_length(self.points(t))

    @property
    def length(self) -> float:
        return float(self.arc()[1][-1])

    def reversed(self) -> Edge:
        return Edge(self.end, self.start, self.kind, self.ctrl[::-1], self.label)

    def mirrored(self) -> Edge:
        """Mirrored in x = 0 and walked the other way (so a mirrored counter-clockwise outline stays one)."""
        flip = np.array([-1.0, 1.0])
        return Edge(self.end * flip, self.start * flip, self.kind, self.ctrl[::-1] * flip, self.label)

    def moved(self, dx: float) -> Edge:
        d = np.array([dx, 0.0])
        return Edge(self.start + d, self.end + d, self.kind, self.ctrl + d, self.label)

    def split(self, at_cm: list[float]) -> list[Edge]:
        """The edge cut at the arc lengths `at_cm` from its start (de Casteljau): consecutive edges."""
        out, rest, done = [], self, 0.0
        for s in sorted(at_cm):
            t_grid, s_grid = rest.arc()
            t = float(np.interp(s - done, s_grid, t_grid))
            levels = [np.vstack([rest.start, rest.ctrl, rest.end])]
            while len(levels[-1]) > 1:
                a = levels[-1]
                levels.append((1 - t) * a[:-1] + t * a[1:])
            left = np.array([lv[0] for lv in levels])  # control polygon of the part before t
            right = np.array([lv[-1] for lv in levels[::-1]])  # ... and after t
            out.append(Edge(left[0], left[-1], rest.kind, left[1:-1], rest.label))
            rest = Edge(right[0], right[-1], rest.kind, right[1:-1], rest.label)
            done = s
        return [*out, rest]


def edges_of(piece: Piece) -> list[Edge]:
    """A piece's outline as Edges (relative control points made absolute), labelled e0, e1, ..."""
    out = []
    for i in range(piece.n_edges):
        p0, p1 = (np.asarray(p, float) for p in piece.edge_endpoints(i))
        c = piece.curves.get(i)
        if c is None:
            out.append(Edge(p0, p1, None, np.zeros((0, 2)), f"e{i}"))
            continue
        if c.type not in ("quadratic", "cubic"):
            raise ValueError(f"{piece.name} edge {i}: {c.type} curves are not handled")
        e = p1 - p0
        n = np.array([-e[1], e[0]])  # to the left of the edge, as long as it
        out.append(Edge(p0, p1, c.type, p0 + c.control[:, :1] * e + c.control[:, 1:] * n, f"e{i}"))
    return out


def piece_of(name: str, edges: list[Edge]) -> Piece:
    """A Piece from consecutive Edges (absolute control points made relative again)."""
    curves = {}
    for i, ed in enumerate(edges):
        if i and not np.allclose(edges[i - 1].end, ed.start, atol=1e-9):
            raise ValueError(f"{name}: edge {i} does not start where edge {i - 1} ends")
        if ed.kind is not None:
            e = ed.end - ed.start
            n = np.array([-e[1], e[0]])
            d = ed.ctrl - ed.start
            curves[i] = Curve(ed.kind, np.c_[d @ e, d @ n] / float(e @ e))
    return Piece(name, np.array([ed.start for ed in edges]), curves)


def unfolded(half: list[Edge], tags: tuple[str, str]) -> list[Edge]:
    """A half piece cut on the fold (hem first, from (0, 0); its last edge runs down x = 0) made whole: the drawn
    half's labels get tags[0], its mirror image's tags[1]; the two hem halves become one edge, the first."""
    hem, *rest, fold = half
    if not (np.allclose(hem.start, 0.0) and hem.kind is None and hem.end[1] == 0.0):
        raise ValueError("the half piece must start with a straight hem from (0, 0)")
    if not (abs(fold.start[0]) < 1e-6 and abs(fold.end[0]) < 1e-6 and fold.kind is None):
        raise ValueError("the fold must be the last edge, straight, on x = 0")
    drawn = [replace(e, label=e.label + tags[0]) for e in rest]
    mirror = [replace(e.mirrored(), label=e.label + tags[1]) for e in reversed(rest)]
    whole_hem = Edge(hem.end * [-1.0, 1.0], hem.end, None, np.zeros((0, 2)), "hem")
    return [whole_hem, *drawn, *mirror]


def match_cuts(chain_a: list[Edge], chain_b: list[Edge]) -> tuple[list[list[Edge]], list[list[Edge]]]:
    """Two chains of edges sewn along one seam, both in the seam's direction, cut so that they have parts of the
    same lengths (their corners matched by the fraction of the seam's length; corners closer than MERGE_CM taken
    as one, each side keeping its own). Returns, per chain, the parts of each edge."""
    len_a, len_b = [e.length for e in chain_a], [e.length for e in chain_b]
    scale = max(sum(len_a), sum(len_b))
    knots_a, knots_b = np.cumsum([0.0, *len_a]) / sum(len_a), np.cumsum([0.0, *len_b]) / sum(len_b)

    def cuts(chain, lengths, own, other):
        """Each edge's parts, cut where `other` has a corner that `own` lacks."""
        start = np.cumsum([0.0, *lengths])
        new = [k for k in other[1:-1] if np.abs(own - k).min() * scale > MERGE_CM]
        out = []
        for e, s0, length in zip(chain, start, lengths):
            at = [k * sum(lengths) - s0 for k in new]
            out.append(e.split([s for s in at if 0.0 < s < length]))
        return out

    return cuts(chain_a, len_a, knots_a, knots_b), cuts(chain_b, len_b, knots_b, knots_a)


def sewn_teagan(svg: str = SVG) -> Pattern:
    """The Teagan T-shirt from its FreeSewing SVG (half front, half back, one sleeve, no seams), sewn: see the
    module docstring."""
    pat = load_pattern(svg)
    front, back, sleeve = (edges_of(pat.piece(n)) for n in ("front", "back", "sleeve"))
    # Outline edges (FreeSewing's drawing, as kitsuke imports it): front/back 0 hem, 1 side, 2-3 armhole (underarm
    # to shoulder), 4 shoulder, 5 neckline, 6 fold; sleeve 0 hem, 1 underarm (front), 2-6 cap (front underarm over
    # the top to the back underarm), 7 underarm (back).
    for edges in (front, back):
        for e, name in zip(edges, ("hem", "side", "arm", "arm", "shoulder", "neck", "fold")):
            e.label = name
    for e, name in zip(sleeve, ("hem", "under_f", "cap", "cap", "cap", "cap", "cap", "under_b")):
        e.label = name

    # Armhole and cap along the seam from the front underarm over the shoulder to the back underarm.
    armhole = [front[2], front[3], back[3].reversed(), back[2].reversed()]
    arm_split, cap_split = match_cuts(armhole, sleeve[2:7])
    n_front = len(arm_split[0]) + len(arm_split[1])  # the armhole's parts on the front
    arm_parts = [p for parts in arm_split for p in parts]
    cap_parts = [p for parts in cap_split for p in parts]
    for k, (a, c) in enumerate(zip(arm_parts, cap_parts)):
        a.label, c.label = f"arm{k}", f"cap{k}"
    front = [*front[:2], *arm_parts[:n_front], *front[4:]]
    back = [*back[:2], *(p.reversed() for p in arm_parts[n_front:][::-1]), *back[4:]]
    sleeve = [*sleeve[:2], *cap_parts, sleeve[7]]

    # Seen from outside, the front's drawn half is the wearer's left (L), the back's the wearer's right (R).
    pieces = {
        "front": unfolded(front, ("L", "R")),
        "back": unfolded(back, ("R", "L")),
        "sleeve_right": [replace(e, label=e.label + "R") for e in sleeve],
        "sleeve_left": [replace(e.mirrored().moved(sleeve[0].end[0]), label=e.label + "L") for e in reversed(sleeve)],
    }

    seams = []

    def sew(a_piece: str, a_label: str, b_piece: str, b_label: str) -> None:
        """Sew two edges (both pieces face outwards, so a's start meets b's end)."""
        a = next(i for i, e in enumerate(pieces[a_piece]) if e.label == a_label)
        b = next(i for i, e in enumerate(pieces[b_piece]) if e.label == b_label)
        la, lb = pieces[a_piece][a].length, pieces[b_piece][b].length
        if abs(la - lb) > SEAM_TOLERANCE * max(la, lb):
            raise ValueError(f"{a_piece} {a_label} ({la:.2f} cm) and {b_piece} {b_label} ({lb:.2f} cm) differ")
        seams.append(Seam(EdgeRef(a_piece, a), EdgeRef(b_piece, b), True))

    for s in ("R", "L"):
        sl = "sleeve_right" if s == "R" else "sleeve_left"
        sew("front", f"side{s}", "back", f"side{s}")
        sew("front", f"shoulder{s}", "back", f"shoulder{s}")
        sew(sl, f"under_f{s}", sl, f"under_b{s}")
        for k in range(len(cap_parts)):
            sew(sl, f"cap{k}{s}", "front" if k < n_front else "back", f"arm{k}{s}")

    sewn = Pattern(
        "teagan_tshirt_cisMaleAdult42",
        [piece_of(name, edges) for name, edges in pieces.items()],
        seams,
        {
            "source": "FreeSewing Teagan T-shirt 4.10.2, measurements cisMaleAdult42 (MIT): "
            "tests/data/pattern/teagan_tshirt_cisMaleAdult42.svg, sewn by tools/make_tshirt_strokes.py",
            "pieces": "front and back unfolded from their cut-on-fold halves (drawn half at x >= 0: the front's is "
            "the wearer's left, the back's the wearer's right); sleeve_right as drawn (front at x > 0), sleeve_left "
            "its mirror image",
            "edges": {name: [e.label for e in edges] for name, edges in pieces.items()},
        },
    )
    issues = validate(sewn)
    if issues:
        raise ValueError("sewn pattern: " + "; ".join(i.message for i in issues))
    return sewn


# -- the strokes --------------------------------------------------------------------------------------------------


def shoulder_seam_from(pat: Pattern, u_cm: float, side: str) -> tuple[np.ndarray, float]:
    """The front's shoulder seam on the wearer's `side` ("R"/"L"): its end at the armhole (2,) cm, and its length
    from where the vertical line |u| = u_cm crosses it to that end, cm."""
    front = pat.piece("front")
    labels = pat.meta["edges"]["front"]
    i = labels.index(f"shoulder{side}")
    p0, p1 = front.edge_endpoints(i)
    arm_end, neck_end = (p0, p1) if abs(p0[0]) > abs(p1[0]) else (p1, p0)
    frac = (abs(arm_end[0]) - u_cm) / (abs(arm_end[0]) - abs(neck_end[0]))
    return arm_end.copy(), frac * front.edge_length(i)


def main(out: str) -> None:
    pat = sewn_teagan()
    save_pattern(pat, SEWN)
    print("wrote", SEWN, len(pat.pieces), "pieces", len(pat.seams), "seams")
    body = default_body()
    sl = Slicer(body.mesh)
    pairs = []
    for side, sgn in (("R", -1.0), ("L", 1.0)):
        # -- torso: front and back, from the shoulder ridge down ------------------------------------------------
        # The front's drawn half (u > 0) is the wearer's left, the back's the wearer's right.
        for name, toward, x in (("front", 1.0, FRONT_X), ("back", -1.0, BACK_X)):
            u = TORSO_U * sgn * toward
            pairs.append(
                torso_pair(
                    len(pairs) + 1,
                    sl,
                    pat.piece(name),
                    u,
                    sgn * x,
                    toward,
                    near_y=SHOULDER_Y,
                    top_gap_cm=TOP_GAP,
                    min_y=CHEST_Y,
                )
            )
        # -- sleeve: along the top of the shoulder and the arm ------------------------------------------------
        # The front stroke puts the shoulder seam at |u| = TORSO_U on the ridge at |x| = FRONT_X; the seam's end
        # lies the rest of its length further out along the top line, and the sleeve's cap point sewn to it there.
        # A stroke each side of the sleeve's middle line (not one along it) wraps the sleeve round the arm: with
        # one, the sleeve grows out flat and its front underarm can close the wrong side of the arm.
        sleeve = f"sleeve_{'right' if side == 'R' else 'left'}"
        arm_end, seam_rest = shoulder_seam_from(pat, TORSO_U, side)
        _, cap_pt = sewn_point(pat, "front", arm_end, to=sleeve)
        xs = sgn * np.arange(FRONT_X, ARM_END_X, 0.005)
        top = smooth(sl.top_line(xs, SHOULDER_Y), 7)
        s_top = arc_length(top)
        piece = pat.piece(sleeve)
        to_front = 1.0 if side == "R" else -1.0  # on the sleeve, the way to the front of the arm
        for toward in (1.0, -1.0):  # in front of, then behind the middle line
            u = cap_pt[0] + to_front * toward * SLEEVE_OFFSET
            drop = cap_pt[1] - pattern_top(piece, u)  # the cap is this much lower at u than at the cap point
            line = sl.around(top, SLEEVE_OFFSET / 100, toward)
            s_line = arc_length(line)
            k0 = int(np.argmin(np.abs(s_top - (seam_rest + drop + END_GAP) / 100)))  # line and top share stations
            v0 = cap_pt[1] - drop - END_GAP
            length = min((v0 - END_GAP) / 100, s_line[-1] - s_line[k0] - 0.01)
            pts = cut(line, s_line[k0], s_line[k0] + length)
            pat_pts = np.c_[np.full(len(pts), u), np.linspace(v0, v0 - 100 * length, len(pts))]
            pairs.append(pair(len(pairs) + 1, sleeve, pat_pts, pts))
    write_strokes_file(
        pairs,
        {
            "pattern": "FreeSewing Teagan T-shirt cisMaleAdult42, sewn: " + SEWN,
            "body": "kitsuke default body (MakeHuman base mesh)",
            "made_by": "tools/make_tshirt_strokes.py",
            "note": "hung from the shoulders: torso strokes from the shoulder ridge down the front and back 1.7 cm "
            "out from the neck point; sleeve strokes 2 cm each side of the sleeve's middle line along the top of "
            "the arm from where the shoulder seam ends; drawn surface points, each pattern stroke as long as its "
            "body stroke",
        },
        out,
    )


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "src/kitsuke/assets/strokes/tshirt_default.json")
