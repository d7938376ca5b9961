"""Generate src/kitsuke/assets/strokes/hoody_mean_all.json: GarmentCode's hoody (a sleeveless top with a hood) on
mean_all, hung from the shoulders with the hood up, resting on the head.

Run from the repository root: python tools/make_hoody_strokes.py [OUT.json]

Strokes (drawn points on the body; each pattern stroke as long as its body stroke), right side first:
  torso panels (4): a vertical line through the middle of the shoulder seam (|u| = 14 cm), from 1.5 cm below the
      seam down the front (back) of the body in the plane |x| = 0.14 m, from 1.5 cm past the shoulder ridge to
      where the chest (shoulder blade) stands out most, not below 1.2 m;
  hood panels (2): the hood's centre seam (crown and back of the head) moved 2.5 cm into the panel, from 2.5 cm
      short of the face opening over the crown down the back of the head; on the body the head's profile in the
      plane |x| = 2.5 cm, the seams' junction (the crown's back end) on the top of the head — where GarmentCode's
      placement puts it too (right above the head's highest point) — down the back to the back of the skull
      (the head's most backward point above the neck).
So the shoulder seams lie on the shoulder ridge and the hood hangs from the crown.
"""

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from _strokes_common import BODY_STEP_M, Slicer, inset_path, pair, torso_pair, write_strokes_file

from kitsuke.body import load_body
from kitsuke.dressing import arc_length, interpolate_polyline
from kitsuke.pattern import load_pattern

BODY = "tests/data/bodies/mean_all.obj"
PATTERN = "tests/data/pattern/hoody_mean_specification.json"
TORSO_U = 14.0  # cm from the centre line: the middle of the 6.9 cm shoulder seam (u 10.8 .. 17.2)
TOP_GAP = 1.5  # cm between a torso stroke's start and the shoulder seam (and, on the body, the ridge)
SHOULDER_Y = 1.43  # m, about the shoulder ridge height (picks the body section)
CHEST_Y = 1.2  # m, torso strokes stop above this height
HOOD_INSET = 2.5  # cm, the hood stroke's distance from the centre seam (and on the body from the midline)
HOOD_FRONT_GAP = 2.5  # cm, the hood stroke stops this far from the face opening
NECK_Y = 1.56  # m, the hood stroke goes no lower on the back of the head than this


def hood_centre_edges(pat, name):
    """The hood's two centre-seam edges (sewn to the other hood) in outline order, and the crown edge's index."""
    edges = sorted(
        ea.edge
        for seam in pat.seams
        for ea, eb in ((seam.a, seam.b), (seam.b, seam.a))
        if ea.piece == name and "hood" in eb.piece and eb.piece != name
    )
    n = pat.piece(name).n_edges
    if len(edges) != 2:
        raise ValueError(f"{name}: expected two centre-seam edges, got {edges}")
    if (edges[0] + 1) % n != edges[1]:
        edges = edges[::-1]  # the chain wraps round the outline's end
    piece = pat.piece(name)
    crown = min(edges, key=piece.edge_length)  # the short one across the top of the head
    return edges, crown


def main(out: str) -> None:
    body = load_body(BODY)
    pat = load_pattern(PATTERN)
    sl = Slicer(body.mesh)
    head_top_y = float(body.mesh.vertices[:, 1].max())
    pairs = []
    for side, sgn in (("right", -1.0), ("left", 1.0)):
        for panel, toward in (("ftorso", 1.0), ("btorso", -1.0)):
            piece = pat.piece(f"{side}_{panel}")
            u = TORSO_U * (1.0 if piece.outline[:, 0].max() > 1 else -1.0)  # toward the side seam
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
                )
            )
        # -- hood: over the crown and down the back of the head ----------------------------------------------
        name = f"{side}_hood"
        piece = pat.piece(name)
        edges, crown = hood_centre_edges(pat, name)
        path = inset_path(piece, edges, HOOD_INSET)
        s = arc_length(path)
        # The junction of the two centre edges (the crown's back end) and which way the crown runs.
        if edges[0] == crown:  # crown first: the path runs face -> junction -> back of the neck
            path, s = path[::-1], s[-1] - s[::-1]
        s_j = float(s[np.argmin(np.linalg.norm(path - piece.edge_endpoints(crown)[edges[0] == crown], axis=1))])
        x = sgn * HOOD_INSET / 100
        front, _ = sl.down_from_ridge(x, 1.0, near_y=head_top_y, start_m=0.0, stop=(s[-1] - s_j - HOOD_FRONT_GAP) / 100)
        back, _ = sl.down_from_ridge(x, -1.0, near_y=head_top_y, start_m=0.0, stop="prominent", min_y=NECK_Y)
        body_path = np.vstack([back[::-1], front[1:]])  # back of the skull -> top -> forehead
        lb, lf = float(arc_length(back)[-1]), float(arc_length(front)[-1])
        n = max(2, int(round((lb + lf) / BODY_STEP_M)) + 1)
        body_pts = interpolate_polyline(body_path, np.linspace(0.0, lb + lf, n))
        pat_pts = interpolate_polyline(path, np.linspace(s_j - 100 * lb, s_j + 100 * lf, n))
        pairs.append(pair(len(pairs) + 1, name, pat_pts, body_pts))
    write_strokes_file(
        pairs,
        {
            "pattern": "GarmentCode hoody_mean_specification.json",
            "body": "GarmentCode mean_all.obj",
            "made_by": "tools/make_hoody_strokes.py",
            "note": "hung from the shoulders, hood up: torso strokes from the shoulder ridge down the front and "
            "back through the middle of the shoulder seam; hood strokes 2.5 cm beside the centre seam from the "
            "forehead over the crown down the back of the head; drawn surface points, each pattern stroke as long "
            "as its body stroke",
        },
        out,
        pat,
    )


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "src/kitsuke/assets/strokes/hoody_mean_all.json")
