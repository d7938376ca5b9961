"""The drag's propagation over the cloth (private: see `kitsuke.dressing.drag`).

- `drag_weights`: the dependency graph from the grab (shortest paths along the cloth, cut at pins) and the weight
  of each vertex, from its distance to the grab and to the nearest pin.
- `body_axis`: the axis of the body part under the grab, about which a drag around it turns the garment.
"""

from __future__ import annotations

from typing import Literal

import numpy as np

from ..cloth import BodyCollider, ClothModel

#: Body vertices farther from a capsule's axis than this many times its radius (plus 2 cm) belong to another part
#: (capsules sit inside the flesh: the default body's hips reach ~3 torso radii from the torso's axis, its hands
#: at hip height ~7).
AXIS_REACH = 4.0


def smooth_falloff(t: np.ndarray) -> np.ndarray:
    """S(t) = 3t² - 2t³ of t clipped to [0, 1]: S(0) = 0, S(1) = 1, S'(0) = S'(1) = 0."""
    t = np.clip(t, 0.0, 1.0)
    return t * t * (3.0 - 2.0 * t)


def drag_weights(
    model: ClothModel,
    grab: int,
    pinned: np.ndarray,
    *,
    falloff: Literal["smooth", "linear"] = "smooth",
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The dependency graph from vertex `grab` and the drag weights.

    Distances run along the cloth's edges at their rest lengths (metres). Edges leaving a pinned vertex are cut, so
    nothing propagates through a pin. With d_g the distance to the grab and d_p the distance to the nearest pin,
    t = d_p / (d_g + d_p) (1 without pins, 0 where only pins lead) and the weight is S(t) (`smooth_falloff`, no
    kink at the grab or at a pin) or t itself (`falloff="linear"`).

    pinned : (V,) bool. Returns weight (V,) in [0, 1], d_g (V,) metres (inf where unreached), d_p (V,) metres (inf
    without pins), parent (V,) int64: each vertex's predecessor on its shortest path from the grab (the dependency
    graph; -1 at the grab and at unreached vertices).
    """
    from scipy.sparse.csgraph import dijkstra

    cut, full = _graphs(model, pinned)
    d_grab, pred = dijkstra(cut, directed=True, indices=int(grab), return_predecessors=True)
    d_pin = _pin_distances(full, pinned)
    weight = _weights(d_grab, d_pin, pinned, falloff)
    parent = np.where(pred < 0, -1, pred).astype(np.int64)
    return weight, d_grab, d_pin, parent


def follow_weights(model: ClothModel, sources: np.ndarray, pinned: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """`drag_weights` from several grabbed vertices at once (the re-wrap's stroke vertices, (V,) bool `sources`):
    the smooth weight (V,) and each vertex's nearest source over the cloth (V,) int64 (-1 where unreached)."""
    from scipy.sparse.csgraph import dijkstra

    cut, full = _graphs(model, pinned)
    d_src, _, nearest = dijkstra(
        cut, directed=True, indices=np.flatnonzero(sources), min_only=True, return_predecessors=True
    )
    weight = _weights(d_src, _pin_distances(full, pinned), pinned, "smooth")
    return weight, np.where(np.isfinite(d_src), nearest, -1).astype(np.int64)


def _graphs(model: ClothModel, pinned: np.ndarray):
    """The cloth's edge graph at rest lengths (metres), both directions: with the edges leaving pins cut, and whole."""
    from scipy.sparse import csr_matrix

    n = model.n_vertices
    e, length = model.edges, model.rest_lengths
    src = np.concatenate([e[:, 0], e[:, 1]])
    dst = np.concatenate([e[:, 1], e[:, 0]])
    w = np.concatenate([length, length])
    keep = ~pinned[src]
    return csr_matrix((w[keep], (src[keep], dst[keep])), shape=(n, n)), csr_matrix((w, (src, dst)), shape=(n, n))


def _pin_distances(full, pinned: np.ndarray) -> np.ndarray:
    from scipy.sparse.csgraph import dijkstra

    if not pinned.any():
        return np.full(len(pinned), np.inf)
    return dijkstra(full, directed=True, indices=np.flatnonzero(pinned), min_only=True)


def _weights(d_src: np.ndarray, d_pin: np.ndarray, pinned: np.ndarray, falloff: str) -> np.ndarray:
    with np.errstate(invalid="ignore", divide="ignore"):
        t = np.where(np.isinf(d_pin), 1.0, d_pin / (d_src + d_pin))
    t = np.where(np.isfinite(d_src), t, 0.0)
    t[pinned] = 0.0
    return smooth_falloff(t) if falloff == "smooth" else np.clip(t, 0.0, 1.0)


def body_axis(collider: BodyCollider, point: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The axis of the body part at body point `point` (3,) metres: (unit direction (3,), a point on it (3,)).

    The part is the capsule ("bone") whose surface is nearest the point; its axis passes through the centroid of
    the body vertices in a slab 4 cm thick across the axis at the point, within `AXIS_REACH` capsule radii of the
    axis (the capsules are fitted inside the flesh, and the torso's is shifted towards the spine: the centroid is
    the middle of the cross-section the cloth goes round). Without capsules: the vertical (Y) through the
    centroid of the body's slice at the point's height.
    """
    p = np.asarray(point, dtype=np.float64)
    v = collider.vertices
    ends, radii = collider.capsule_ends, collider.capsule_radii
    if len(ends):
        k = int(nearest_capsule(collider, p[None])[0])
        a, ab = ends[k, 0], ends[k, 1] - ends[k, 0]
        t = float(np.clip((p - a) @ ab / max(ab @ ab, 1e-300), 0.0, 1.0))
        foot = a + t * ab
        r = radii[k, 0] + t * (radii[k, 1] - radii[k, 0])
        axis = ab / np.linalg.norm(ab)
        rel = v - foot
        along = rel @ axis
        radial = np.linalg.norm(rel - along[:, None] * axis, axis=1)
        near = (np.abs(along - (p - foot) @ axis) < 0.02) & (radial < AXIS_REACH * max(r, 0.01) + 0.02)
    else:
        axis = np.array([0.0, 1.0, 0.0])
        near = np.abs(v[:, 1] - p[1]) < 0.02
    centre = v[near].mean(axis=0) if near.any() else p
    return axis, centre


def nearest_capsule(collider: BodyCollider, points: np.ndarray) -> np.ndarray:
    """The capsule ("bone") whose surface is nearest each of `points` (n, 3) metres: (n,) int64 (-1 without
    capsules)."""
    p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    ends, radii = collider.capsule_ends, collider.capsule_radii
    if not len(ends):
        return np.full(len(p), -1, dtype=np.int64)
    a, ab = ends[:, 0], ends[:, 1] - ends[:, 0]  # (C, 3)
    rel = p[:, None, :] - a[None]  # (n, C, 3)
    t = np.clip(np.einsum("ncj,cj->nc", rel, ab) / np.maximum(np.einsum("cj,cj->c", ab, ab), 1e-300), 0.0, 1.0)
    gap = np.linalg.norm(rel - t[..., None] * ab[None], axis=2) - (radii[:, 0] + t * (radii[:, 1] - radii[:, 0]))
    return np.argmin(gap, axis=1).astype(np.int64)


#: Capsules whose cloth turns together (a tube round both legs turns with the torso about its axis; a sleeve round
#: one arm cannot): each arm is a limb of its own, everything else (torso, neck, thighs, shins) the trunk.
ARM_LIMBS = {"l_upper_arm": 1, "l_forearm": 1, "r_upper_arm": 2, "r_forearm": 2}


def capsule_limbs(names: list[str], n_capsules: int) -> np.ndarray:
    """Each capsule's limb (`ARM_LIMBS`; 0 the trunk): (n_capsules,) int64. Without names (a collider built
    without a rig's capsules): all 0."""
    if len(names) != n_capsules:
        return np.zeros(n_capsules, dtype=np.int64)
    return np.array([ARM_LIMBS.get(n, 0) for n in names], dtype=np.int64)


def turn_weights(model: ClothModel, limb: np.ndarray, near: np.ndarray, grab: int, blend_m: float) -> np.ndarray:
    """How much of a drag's turn about the grabbed body part's axis each vertex takes: (V,) in [0, 1].

    limb : (V,) int64, the limb (`capsule_limbs`) of each vertex's foot, trusted where `near` (V,) bool (cloth
    near the body); cloth away from it takes the limb of the nearest such vertex along the cloth (a hanging
    sleeve is the arm's, wherever its nearest skin is). Cloth on the grab's limb turns (1), blended to 0 over
    `blend_m` metres of cloth towards cloth on another limb, which does not turn (0): the kimono's body turns
    about the torso while its sleeves stay round the arms.
    """
    from scipy.sparse.csgraph import dijkstra

    if not near.any() or (limb[near] == limb[near][0]).all():
        return np.ones(model.n_vertices)
    _, full = _graphs(model, np.zeros(model.n_vertices, dtype=bool))
    d, _, source = dijkstra(full, directed=True, indices=np.flatnonzero(near), min_only=True, return_predecessors=True)
    of = np.where(np.isfinite(d), limb[np.maximum(source, 0)], limb[grab])
    of[near] = limb[near]
    own = of == of[grab]
    if own.all():
        return np.ones(model.n_vertices)
    d_other = dijkstra(full, directed=True, indices=np.flatnonzero(~own), min_only=True)
    return np.where(own, smooth_falloff(d_other / blend_m), 0.0)
