"""Generate src/kitsuke/assets/strokes/shirt_mean_all.json: GarmentCode's shirt on mean_all, hung from the shoulders.

Run from the repository root: python tools/make_shirt_strokes.py [OUT.json]

Strokes (drawn points on the body; each pattern stroke as long as its body stroke), right side first:
  torso panels (4): a vertical line through the middle of the shoulder seam (|u| = 15 cm), from 1.5 cm below
      the seam down the front (back) of the body in the plane |x| = 0.15 m, from 1.5 cm past the shoulder ridge
      to where the chest (shoulder blade) stands out most, not below 1.2 m;
  sleeve panels (4): a line 2.5 cm below the sleeve's top seam, from 1.5 cm off the armhole to 1.5 cm short of
      the cuff, on the body 2.5 cm in front of (behind) the line along the top of the shoulder and the arm,
      starting where the torso's shoulder point (|x| = 0.172 m, its placement) meets that line.
So the shoulder seams lie on the shoulder ridge and the sleeves' top seams along the top of the arms, where the
shirt hangs under gravity.
"""

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from _strokes_common import (
    Slicer,
    cut,
    edge_crossing,
    pair,
    sewn_point,
    smooth,
    torso_pair,
    write_strokes_file,
)

from kitsuke.body import load_body
from kitsuke.dressing import arc_length
from kitsuke.pattern import load_pattern

BODY = "tests/data/bodies/mean_all.obj"
PATTERN = "tests/data/pattern/shirt_mean_specification.json"
TORSO_U = 15.0  # cm from the centre line: the middle of the 4.4 cm shoulder seam (u 12.8 .. 17.2)
TOP_GAP = 1.5  # cm between a torso stroke's start and the shoulder seam (and, on the body, the ridge)
SHOULDER_Y = 1.43  # m, about the shoulder ridge height (picks the body section)
CHEST_Y = 1.2  # m, torso strokes stop above this height
SLEEVE_V = -2.5  # cm, the sleeve stroke's distance from the top seam (v = 0)
END_GAP = 1.5  # cm, sleeve strokes keep this far from the armhole and the cuff
FRONT_SHORT = 0.0  # m, front torso strokes stop this much above the chest's most prominent point


def main(out: str) -> None:
    body = load_body(BODY)
    pat = load_pattern(PATTERN)
    sl = Slicer(body.mesh)
    pairs = []
    for side, sgn in (("right", -1.0), ("left", 1.0)):
        # -- torso: front and back ------------------------------------------------------------------------------
        for panel, toward in (("ftorso", 1.0), ("btorso", -1.0)):
            piece = pat.piece(f"{side}_{panel}")
            u = TORSO_U * (1.0 if piece.outline[:, 0].max() > 1 else -1.0)  # toward the side seam
            short = FRONT_SHORT if toward > 0 else 0.0
            pairs.append(
                torso_pair(
                    len(pairs) + 1,
                    sl,
                    piece,
                    u,
                    sgn * TORSO_U / 100,
                    toward,
                    near_y=SHOULDER_Y,
                    top_gap_cm=TOP_GAP,
                    min_y=CHEST_Y,
                    short_m=short,
                )
            )
        # -- sleeves: along the top of the arm, in front of / behind the top seam --------------------------------
        # The sleeve's top corner at the shoulder end is sewn to the torso's shoulder point: where that hangs
        # across (|x|) is taken from the pattern's own placement of the torso (0.172 m).
        sleeve = pat.piece(f"{side}_sleeve_f")
        corner = sleeve.outline[np.argmax(np.abs(sleeve.outline[:, 0]) - np.abs(sleeve.outline[:, 1]))]
        torso, at = sewn_point(pat, sleeve.name, corner, to="torso")
        x_sp = abs(float(pat.piece(torso).placement.apply(at)[0, 0]))
        xs = sgn * np.arange(x_sp - 0.03, 0.62, 0.005)
        top = smooth(sl.top_line(xs, SHOULDER_Y), 5)
        s_top = arc_length(top)
        s_sp = float(np.interp(x_sp, np.abs(xs), s_top))  # the torso's shoulder point on the top line
        for panel, toward in (("sleeve_f", 1.0), ("sleeve_b", -1.0)):
            name = f"{side}_{panel}"
            piece = pat.piece(name)
            lo, hi = piece.outline.min(0), piece.outline.max(0)
            u_sh = lo[0] if abs(lo[0]) > abs(hi[0]) else hi[0]  # the top corner at the shoulder end
            d = -np.sign(u_sh)  # pattern direction from the shoulder to the cuff
            u_arm = edge_crossing(piece, SLEEVE_V, u_sh)  # the armhole edge at the stroke's height
            u0, u1 = u_arm + d * END_GAP, -d * END_GAP  # cuff at u = 0
            line = sl.around(top, -SLEEVE_V / 100, toward)
            s_line = arc_length(line)
            k0 = int(np.argmin(np.abs(s_top - (s_sp + abs(u0 - u_sh) / 100))))
            length = min(abs(u1 - u0) / 100, s_line[-1] - s_line[k0] - 0.01)
            pts = cut(line, s_line[k0], s_line[k0] + length)
            pat_pts = np.c_[np.linspace(u0, u0 + d * 100 * length, len(pts)), np.full(len(pts), SLEEVE_V)]
            pairs.append(pair(len(pairs) + 1, name, pat_pts, pts))
    write_strokes_file(
        pairs,
        {
            "pattern": "GarmentCode shirt_mean_specification.json",
            "body": "GarmentCode mean_all.obj",
            "made_by": "tools/make_shirt_strokes.py",
            "note": "hung from the shoulders: torso strokes from the shoulder ridge down the front and back "
            "through the middle of the shoulder seam; sleeve strokes 2.5 cm below the sleeves' top seams along the "
            "top of the arms from the shoulder point; drawn surface points, each pattern stroke as long as its "
            "body stroke",
        },
        out,
        pat,
    )


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "src/kitsuke/assets/strokes/shirt_mean_all.json")
