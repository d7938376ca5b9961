"""Layer order of layered cloth (SPEC §5.4: a kimono's left front over its right): how far each vertex of one layer
lies on the wrong side of another layer."""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..geometry import TriMesh

#: Another layer's face counts within this distance of a vertex, metres.
LAYER_REACH_M = 0.03
#: A vertex counts as over or under that face when it lies within its border, give or take half its height above it
#: plus 1 mm (beside the border it is not between the layers).
BORDER_SLACK_M = 0.001
#: Near the body (metres) a face turned inside out is judged by the body: out is away from it. The kimono's right
#: collar lies inside out where the collars cross, 2-3 cm off the chest: at 2 cm, a left-front vertex 21 mm off
#: the body and radially 2-14 mm outside the right front's vertices there read as 10 mm on the wrong side (one body
#: of four moved by 1 nm); farther than 3 cm the nearest body point says less about which way is out.
BODY_REACH_M = 0.03


def wrong_side_mm(
    positions: np.ndarray,
    faces: np.ndarray,
    face_layer: np.ndarray,
    mine: int,
    other: int,
    body: TriMesh | None = None,
) -> np.ndarray:
    """Millimetres by which each vertex of layer `mine` (its faces all of that layer) lying over or under a face of
    layer `other` is on the wrong side of it (0 where it is on the right side or not over it): the higher layer
    must lie outside the lower one. Outside is along the face's winding or, with `body`, away from the body where
    the vertex is within BODY_REACH_M of it and the face is turned inside out (normal more than 120 degrees from
    the body's outward direction there). body : anything with `vertices` (n, 3) and `faces` (m, 3) (a TriMesh, a
    BodyCollider). Returns (Q,) float64 for the vertices of layer `mine`, in index order.
    """
    import igl

    pos = np.asarray(positions, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    fl = np.asarray(face_layer)
    if fl.shape != (len(f),):
        raise InputError(f"face_layer must have shape ({len(f)},), got {fl.shape}")
    # A vertex's layer where all its faces share one (the lowest and highest of its faces' layers agree).
    lo = np.full(len(pos), np.iinfo(np.int64).max)
    hi = np.full(len(pos), np.iinfo(np.int64).min)
    corner_layer = np.repeat(fl.astype(np.int64), 3)
    np.minimum.at(lo, f.reshape(-1), corner_layer)
    np.maximum.at(hi, f.reshape(-1), corner_layer)
    q = np.flatnonzero((lo == mine) & (hi == mine))
    theirs = f[fl == other]
    if not len(q) or not len(theirs):
        return np.zeros(len(q))
    d2, fi, cp = igl.point_mesh_squared_distance(pos[q], pos, theirs)
    tri = pos[theirs[fi]]
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    n /= np.maximum(np.linalg.norm(n, axis=1), 1e-300)[:, None]
    if body is not None:
        bd2, _, bcp = igl.point_mesh_squared_distance(pos[q], body.vertices, body.faces)
        out = (pos[q] - bcp) / np.maximum(np.sqrt(bd2), 1e-12)[:, None]
        turned = (bd2 < BODY_REACH_M**2) & (np.einsum("ij,ij->i", n, out) < -0.5)
        n[turned] *= -1.0
    h = np.einsum("ij,ij->i", pos[q] - cp, n)
    between = (d2 < LAYER_REACH_M**2) & (d2 - h * h < (0.5 * np.abs(h) + BORDER_SLACK_M) ** 2)
    wrong = -h if mine > other else h
    return np.where(between, np.maximum(wrong, 0.0), 0.0) * 1e3


def layer_crossing_mm(positions: np.ndarray, faces: np.ndarray, face_layer: np.ndarray | None, body=None) -> float:
    """The deepest a vertex of any layer lies on the wrong side of any other layer, mm (0 without layers)."""
    if face_layer is None:
        return 0.0
    layers = [int(x) for x in np.unique(face_layer) if x > 0]
    worst = 0.0
    for a in layers:
        for b in layers:
            if a != b:
                worst = max(worst, float(wrong_side_mm(positions, faces, face_layer, a, b, body).max(initial=0.0)))
    return worst
