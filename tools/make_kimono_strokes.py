"""Build src/kitsuke/assets/strokes/kimono_default.json: the kimono (default_kimono(): cut to the default body) on default_body().

Run from the repository root: python tools/make_kimono_strokes.py [OUT.json]

Strokes, per side (right = wearer's right = world -x):
  back   : centre back of each migoro (1.5 cm in from the back seam) down the spine line (drawn points)
  front  : laser "first" rays from the front at |x| = FRONT_X, migoro front half, chest to waist
  back2  : the same rays, "last" hit: the migoro back half over the shoulder blade
  shoulder: migoro shoulder fold line (y = L) along the top of the shoulder (drawn points)
  sleeve : the sleeve crease (y = D) along the top of the arm to near the wrist (drawn points)
Pattern coordinates come from surface arc lengths, so each pattern stroke is as long as its body stroke.
"""

import sys

import numpy as np

from kitsuke.body import default_body
from kitsuke.dressing import arc_length, resample_polyline, strokes_from_dict, write_strokes
from kitsuke.geometry.surface import Surface
from kitsuke.pattern import default_kimono
from kitsuke.skeleton import INDEX

body = default_body()
S = Surface(body.mesh)
J = body.rig.joints
pat = default_kimono()
size = pat.meta["kimono"]["size"]
L, K, W, D, n_neck, k_back = (
    size[k] for k in ("length", "shoulder", "sleeve_width", "sleeve_depth", "neck_width", "back_neck_drop")
)
FRONT_X = 0.075
#: Where the shoulder stroke starts, cm past the neck point along the shoulder fold (see below).
SHOULDER_FROM_NECK = 6.0


def radial_profile(x, c_y, c_z, thetas):
    """Surface points in the plane x = const, where rays from (x, c_y, c_z) inside the torso leave it."""
    u = np.c_[np.zeros_like(thetas), np.sin(thetas), np.cos(thetas)]
    c = np.array([x, c_y, c_z])
    sp = S.cast(np.tile(c, (len(u), 1)), u, hit="first")
    assert sp.hit.all(), (x, thetas[~sp.hit])
    return sp.points


def ridge_profile(x):
    """Closed-ish profile over the shoulder at x: from the front (low) over the ridge to the back (low).
    Returns points ordered front -> back and the index of the ridge (highest point)."""
    th = np.radians(np.linspace(-20, 200, 600))
    p = radial_profile(x, 1.28, 0.03, th)
    return p, int(np.argmax(p[:, 1]))


def s_from_ridge(profile, ridge, y, side):
    """Arc length along the profile from the ridge to where it reaches height y on the front/back."""
    s = arc_length(profile)
    if side == "front":
        idx = np.arange(ridge, -1, -1)
    else:
        idx = np.arange(ridge, len(profile))
    ys = profile[idx, 1]
    j = int(np.argmax(ys <= y))
    # interpolate between idx[j-1] and idx[j]
    a, b = idx[j - 1], idx[j]
    t = (profile[a, 1] - y) / (profile[a, 1] - profile[b, 1])
    return abs((s[a] + t * (s[b] - s[a])) - s[ridge])


pairs = []
meta_notes = {}


def add(pid, piece, pts2, body_dict):
    pairs.append({"id": pid, "pattern": {"piece": piece, "points": np.round(pts2, 2).tolist()}, "body": body_dict})


def rnd(a, d=4):
    return np.round(np.asarray(a, dtype=float), d).tolist()


for side, sgn in (("right", -1.0), ("left", 1.0)):
    mig, sode = f"migoro_{side}", f"sode_{side}"
    # pattern x of a point at distance u (cm) from the centre line, on the migoro / the sleeve
    mig_x = (lambda u: K - u) if side == "right" else (lambda u: u)
    sode_x = (lambda u: W - (u - K)) if side == "right" else (lambda u: u - K)

    # -- shoulder + sleeve ridge path ---------------------------------------------------------------------
    guide = np.array(
        [
            [sgn * 0.08, J[INDEX["neck"]][1] - 0.03, 0.012],
            J[INDEX[f"{side[0]}_shoulder"]],
            J[INDEX[f"{side[0]}_elbow"]],
            J[INDEX[f"{side[0]}_wrist"]],
        ]
    )
    g = resample_polyline(guide, 200)
    d = np.gradient(g, axis=0)
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    up = np.array([0, 1.0, 0])
    nrm = up - (d @ up)[:, None] * d
    nrm /= np.linalg.norm(nrm, axis=1, keepdims=True)
    # Smooth the ray directions across the shoulder and the elbow (~6 cm), so the hits move continuously.
    ker = np.ones(21) / 21
    nrm = np.stack([np.convolve(np.pad(nrm[:, i], 10, mode="edge"), ker, mode="valid") for i in range(3)], axis=1)
    nrm /= np.linalg.norm(nrm, axis=1, keepdims=True)
    sp = S.cast(g + 0.4 * nrm, -nrm, hit="first")
    assert sp.hit.all()
    path = sp.points
    seg = np.linalg.norm(np.diff(path, axis=0), axis=1)
    print(side, "path steps: median", round(1000 * np.median(seg), 2), "mm, max", round(1000 * seg.max(), 2), "mm")
    # keep the path monotone outwards and smooth: drop points that step back
    s = arc_length(path)
    u0 = 100 * abs(path[0, 0])  # distance of the first point from the centre line, cm
    u = u0 + 100 * s
    print(
        side,
        "path start",
        np.round(path[0], 3),
        "u0",
        round(u0, 1),
        "path end u",
        round(u[-1], 1),
        "wrist",
        np.round(J[INDEX[f"{side[0]}_wrist"]], 3),
        "end",
        np.round(path[-1], 3),
    )
    # shoulder stroke: u from SHOULDER_FROM_NECK past the neck point to K - 1.5. Held right beside the neck point
    # (1.5 cm), the fold line pinned the cloth where the collar turns round the neck and the kimono's max strain
    # stayed there: 14.1-14.4 % over six bodies moved by 1 nm; from 4 / 5 / 6 cm: 5.1 / 4.9-18.9 / 4.8-4.9 %.
    sel_sh = (u >= n_neck + SHOULDER_FROM_NECK) & (u <= K - 1.5)
    sel_sl = (u >= K + 1.5) & (u <= K + W - 3.0)
    sh_idx = np.flatnonzero(sel_sh)[:: max(1, sel_sh.sum() // 8)]
    sl_idx = np.flatnonzero(sel_sl)[:: max(1, sel_sl.sum() // 10)]
    sh_idx = np.unique(np.r_[sh_idx, np.flatnonzero(sel_sh)[-1]])
    sl_idx = np.unique(np.r_[sl_idx, np.flatnonzero(sel_sl)[-1]])
    add(len(pairs) + 1, mig, np.c_[mig_x(u[sh_idx]), np.full(len(sh_idx), L)], {"points": rnd(path[sh_idx])})
    add(len(pairs) + 1, sode, np.c_[sode_x(u[sl_idx]), np.full(len(sl_idx), D)], {"points": rnd(path[sl_idx])})
    meta_notes[f"{side}_sleeve_end_u_cm"] = float(u[sl_idx[-1]])

    # -- front and back at |x| = FRONT_X: laser rays ----------------------------------------------------------
    x = sgn * FRONT_X
    prof, ridge = ridge_profile(x)
    print(side, "ridge at", np.round(prof[ridge], 3))
    u_front = 100 * abs(x)
    ys = np.arange(1.32, 0.999, -0.04)
    rays = np.c_[
        np.full_like(ys, x), ys, np.full_like(ys, 1.0), np.zeros_like(ys), np.zeros_like(ys), -np.ones_like(ys)
    ]
    first = S.cast(rays[:, :3], rays[:, 3:], hit="first").points
    # pattern y: ridge distance to the first ray's point, then surface arc length of the laser stroke (densified)
    s0 = s_from_ridge(prof, ridge, first[0, 1], "front")
    dense_y = np.arange(1.32, 0.999, -0.005)
    dense = S.cast(
        np.c_[np.full_like(dense_y, x), dense_y, np.ones_like(dense_y)],
        np.tile([0, 0, -1.0], (len(dense_y), 1)),
        hit="first",
    ).points
    sd = arc_length(dense)
    s_pts = np.interp(-ys, -dense_y, sd)
    add(
        len(pairs) + 1,
        mig,
        np.c_[np.full(len(ys), mig_x(u_front)), L - 100 * s0 - 100 * s_pts],
        {"laser": {"rays": rnd(rays, 3), "hit": "first"}},
    )
    print(side, "front ridge->start", round(100 * s0, 1), "cm, stroke", round(100 * sd[-1], 1), "cm")

    # back at the same x, laser last, upper back only (the waist is narrower than FRONT_X lower down)
    ys_b = np.arange(1.34, 1.139, -0.04)
    rays_b = np.c_[
        np.full_like(ys_b, x),
        ys_b,
        np.full_like(ys_b, 1.0),
        np.zeros_like(ys_b),
        np.zeros_like(ys_b),
        -np.ones_like(ys_b),
    ]
    last = S.cast(rays_b[:, :3], rays_b[:, 3:], hit="last").points
    s0b = s_from_ridge(prof, ridge, last[0, 1], "back")
    dense_yb = np.arange(1.34, 1.139, -0.005)
    denseb = S.cast(
        np.c_[np.full_like(dense_yb, x), dense_yb, np.ones_like(dense_yb)],
        np.tile([0, 0, -1.0], (len(dense_yb), 1)),
        hit="last",
    ).points
    sdb = arc_length(denseb)
    sb = np.interp(-ys_b, -dense_yb, sdb)
    add(
        len(pairs) + 1,
        mig,
        np.c_[np.full(len(ys_b), mig_x(u_front)), L + 100 * s0b + 100 * sb],
        {"laser": {"rays": rnd(rays_b, 3), "hit": "last"}},
    )
    print(
        side,
        "back ridge->start",
        round(100 * s0b, 1),
        "cm, stroke",
        round(100 * sdb[-1], 1),
        "cm",
        "back pts z",
        np.round(last[:, 2], 3),
    )

    # -- centre back: spine line, drawn points -------------------------------------------------------------
    xb = sgn * 0.015
    ys_s = np.arange(1.38, 0.999, -0.005)
    sp_b = S.cast(
        np.c_[np.full_like(ys_s, xb), ys_s, np.ones_like(ys_s)], np.tile([0, 0, -1.0], (len(ys_s), 1)), hit="last"
    ).points
    ss = arc_length(sp_b)
    pick = np.unique(np.r_[np.arange(0, len(ys_s), 8), len(ys_s) - 1])
    # back neck: the pattern's back neck edge meets the centre at y = L + k; start 2 cm below it
    y0 = L + k_back + 2.0
    add(len(pairs) + 1, mig, np.c_[np.full(len(pick), mig_x(1.5)), y0 + 100 * ss[pick]], {"points": rnd(sp_b[pick])})
    print(side, "spine stroke", round(100 * ss[-1], 1), "cm")


# Drawing order: centre backs, shoulders, fronts, backs, sleeves (right before left); ids renumbered.
def kind(p):
    piece, pts = p["pattern"]["piece"], np.array(p["pattern"]["points"])
    if piece.startswith("sode"):
        return 4
    if np.allclose(pts[:, 1], L):
        return 1
    if "laser" in p["body"]:
        return 2 if p["body"]["laser"]["hit"] == "first" else 3
    return 0


pairs.sort(key=lambda p: (kind(p), p["pattern"]["piece"].endswith("left")))
for i, p in enumerate(pairs):
    p["id"] = i + 1

doc = {
    "format": "kitsuke.strokes",
    "version": 1,
    "target": "body",
    "pairs": pairs,
    "meta": {
        "pattern": "kimono (kitsuke pattern kimono, standard size 158/63/31/49)",
        "body": "default body (MakeHuman base mesh, A-pose)",
        "order": "centre back (spine), shoulders, fronts, backs, sleeves; right side first",
        "note": "First strokes, made from the default body's surface (pattern lengths = surface arc "
        "lengths): per side the shoulder fold along the top of the shoulder, the sleeve crease along the top of the "
        "arm, the front panel down the chest (laser, first hit), the back panel over the shoulder blade (same rays, "
        "last hit) and the centre back down the spine.",
    },
}
out = sys.argv[1] if len(sys.argv) > 1 else "src/kitsuke/assets/strokes/kimono_default.json"

write_strokes(strokes_from_dict(doc), out)
print("wrote", out, len(pairs), "pairs")
