"""Generate src/kitsuke/assets/strokes/shirt_mean_all.json: GarmentCode's shirt on mean_all (laser strokes from the front,
length-matched on the surface).

Run from the repository root: python tools/make_shirt_strokes.py src/kitsuke/assets/strokes/shirt_mean_all.json
"""

import json
import sys

import numpy as np

from kitsuke.body import load_body
from kitsuke.dressing import surface_length
from kitsuke.geometry.surface import Surface
from kitsuke.pattern import load_pattern, mesh_pattern

b = load_body("tests/data/bodies/mean_all.obj")
v = b.mesh.vertices
surf = Surface(b.mesh)
pat = load_pattern("tests/data/pattern/shirt_mean_specification.json")
pm = mesh_pattern(pat)


def arm_y(x):
    out = []
    for xi in np.atleast_1d(x):
        s = v[(np.abs(np.abs(v[:, 0]) - abs(xi)) < 0.008) & (v[:, 1] > 0.9) & (np.sign(v[:, 0]) == np.sign(xi))]
        out.append(0.5 * (s[:, 1].min() + s[:, 1].max()))
    return np.array(out)


def affine(name):
    k = pm.piece_names.index(name)
    v0, v1 = pm.piece_vertices[k]
    A = np.c_[pm.vertices_cm[v0:v1], np.ones(v1 - v0)]
    return np.linalg.lstsq(A, pm.positions_m[v0:v1], rcond=None)[0]


def match_length(make_rays, hit, target_m, lo=0.3, hi=1.5):
    """Scale factor of the body stroke so that its surface length matches target_m (bisection)."""
    for _ in range(30):
        mid = 0.5 * (lo + hi)
        r = make_rays(mid)
        sp = surf.cast(r[:, :3], r[:, 3:], hit=hit)
        L = surface_length(surf, sp.points)
        lo, hi = (mid, hi) if L < target_m else (lo, mid)
    return 0.5 * (lo + hi)


pairs = []
sid = 1
n = 9
for name in pm.piece_names:
    k = pm.piece_names.index(name)
    v0, v1 = pm.piece_vertices[k]
    cm = pm.vertices_cm[v0:v1]
    lo_, hi_ = cm.min(0), cm.max(0)
    M = affine(name)
    if "torso" in name:
        front = "ftorso" in name
        u = -9.0 if lo_[0] < -1 else 9.0
        x0 = (np.array([u, 0, 1]) @ M)[0]
        zs = 1.0 if front else -1.0
        v_top = 36.5 if front else 41.0
        angles = [30.0, 50.0] if front else [30.0, 50.0, 65.0]

        def rays(y_lo):
            ys = np.linspace(y_lo, 1.36, 7)
            r = [[x0, y, zs, 0, 0, -zs] for y in ys]
            for a in np.radians(angles):
                d = np.array([0, np.sin(a), zs * np.cos(a)])
                o = np.array([x0, 1.36, 0.0]) + d
                r.append([*o, *(-d)])
            return np.array(r)

        lo_y, hi_y = 0.9, 1.3
        for _ in range(30):
            mid = 0.5 * (lo_y + hi_y)
            r = rays(mid)
            L = surface_length(surf, surf.cast(r[:, :3], r[:, 3:], hit="first").points)
            lo_y, hi_y = (lo_y, mid) if 100 * L < v_top - 4.0 else (mid, hi_y)
        r = rays(0.5 * (lo_y + hi_y))
        L = surface_length(surf, surf.cast(r[:, :3], r[:, 3:], hit="first").points)
        pattern_pts = np.c_[np.full(len(r), u), np.linspace(4.0, 4.0 + 100 * L, len(r))]
        pairs.append(
            {
                "id": sid,
                "pattern": {"piece": name, "points": np.round(pattern_pts, 3).tolist()},
                "body": {"laser": {"rays": np.round(r, 4).tolist(), "hit": "first"}},
            }
        )
        print(name, "y_lo", round(0.5 * (lo_y + hi_y), 3), "L", round(L, 3))
        sid += 1
        continue
    else:
        # sleeve: along the long axis (u), at mid width
        vm = 0.5 * (lo_[1] + hi_[1])
        ua, ub = lo_[0] + 3.0, hi_[0] - 3.0
        xa, xb = (np.array([ua, vm, 1]) @ M)[0], (np.array([ub, vm, 1]) @ M)[0]
        if abs(xa) > abs(xb):
            ua, ub, xa, xb = ub, ua, xb, xa  # from shoulder to cuff
        Lp = abs(ub - ua) / 100
        hit = "first" if name.endswith("_f") else "last"

        def rays(s, xa=xa, xb=xb):
            xs = xa + s * np.linspace(0, 1, n) * (xb - xa)
            return np.c_[xs, arm_y(xs), np.full(n, 1.0), np.zeros(n), np.zeros(n), -np.ones(n)]

        s = match_length(rays, hit, Lp, lo=0.5, hi=1.6)
        pattern_pts = np.c_[np.linspace(ua, ub, n), np.full(n, vm)]
        r = rays(s)
    pairs.append(
        {
            "id": sid,
            "pattern": {"piece": name, "points": np.round(pattern_pts, 3).tolist()},
            "body": {"laser": {"rays": np.round(r, 4).tolist(), "hit": hit}},
        }
    )
    print(
        name,
        hit,
        "scale",
        round(s, 3),
        "pattern",
        pattern_pts[[0, -1]].round(1).tolist(),
        "x",
        r[[0, -1], 0].round(3).tolist(),
        "y",
        r[[0, -1], 1].round(3).tolist(),
    )
    sid += 1
doc = {
    "format": "kitsuke.strokes",
    "version": 1,
    "target": "body",
    "pairs": pairs,
    "meta": {
        "pattern": "GarmentCode shirt_mean_specification.json",
        "body": "GarmentCode mean_all.obj",
        "note": "laser strokes from the front: torso panels vertical a third in from the centre line, sleeves along the arm; body strokes length-matched on the surface",
    },
}
json.dump(doc, open(sys.argv[1], "w"), indent=1)
