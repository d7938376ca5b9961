"""The polish's energy terms (see `kitsuke.cloth._polish`), compiled (numba): each adds its gradient to an
array and returns its value; `polish_energy` sums them for one configuration of the cloth.

x, grad : (V, 3) float64 metres / energy per metre. Weights are per term; the polish's module docstring says
what each term is for and why its weight is what it is.
"""

from __future__ import annotations

import numba
import numpy as np

from ._model import ClothModel


def _cotangents(rest_corners: np.ndarray) -> np.ndarray:
    """(F, 3) cotangent of each rest triangle's angle at corner k; rest_corners (F, 3, 2) metres."""
    out = np.empty(rest_corners.shape[:2])
    for k in range(3):
        a = rest_corners[:, (k + 1) % 3] - rest_corners[:, k]
        b = rest_corners[:, (k + 2) % 3] - rest_corners[:, k]
        cross = np.abs(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0])
        out[:, k] = np.einsum("ij,ij->i", a, b) / np.maximum(cross, 1e-300)
    return out


def bending_stencil(model: ClothModel) -> tuple[np.ndarray, np.ndarray]:
    """The quadratic bending model (Bergou et al. 2006) per hinge: (weights (H, 4), coef (H,)) such that the
    bending energy of x (V, 3) metres is sum_h coef_h |k_h|^2 with k_h = sum_i weights[h, i] x[hinges[h, i]] over
    the hinge's vertices a, b, c, d (`ClothModel.hinges`). The weights are (-(cot b1 + cot b2), -(cot a1 + cot a2),
    cot a1 + cot b1, cot a2 + cot b2) / |e| (the angles at a and b in each of the hinge's two rest triangles) and
    coef = 3 |e|^2 / (A1 + A2). k vanishes for any flat placement of the hinge (the weights make the vector from
    the edge to c over c's height, minus the same for d), so the energy is zero on flat cloth and isometric bends
    cost about their dihedral angle squared; it is quadratic in x (x^T Q x for a constant sparse Q).
    """
    h, hf = model.hinges, model.hinge_faces
    if not len(h):
        return np.zeros((0, 4)), np.zeros(0)
    cots = _cotangents(model.rest_corners)

    def corner(f: np.ndarray, v: np.ndarray) -> np.ndarray:
        return np.argmax(model.faces[f] == v[:, None], axis=1)

    f1, f2 = hf[:, 0], hf[:, 1]
    a, b = h[:, 0], h[:, 1]
    ca1, cb1 = cots[f1, corner(f1, a)], cots[f1, corner(f1, b)]
    ca2, cb2 = cots[f2, corner(f2, a)], cots[f2, corner(f2, b)]
    rc = model.rest_corners
    e = np.linalg.norm(rc[f1, corner(f1, a)] - rc[f1, corner(f1, b)], axis=1)
    w = np.stack([-(cb1 + cb2), -(ca1 + ca2), ca1 + cb1, ca2 + cb2], axis=1) / e[:, None]
    coef = 3.0 * e**2 / (model.rest_areas[f1] + model.rest_areas[f2])
    return np.ascontiguousarray(w), coef


@numba.njit(cache=True)
def bend_energy(x, hinges, weights, coef, grad):  # pragma: no cover - numba
    """Bending energy sum_h coef[h] |k_h|^2 of x (V, 3) (see `bending_stencil`); adds its gradient to grad."""
    total = 0.0
    k = np.zeros(3)
    for h in range(hinges.shape[0]):
        for c in range(3):
            k[c] = 0.0
            for i in range(4):
                k[c] += weights[h, i] * x[hinges[h, i], c]
        total += coef[h] * (k[0] * k[0] + k[1] * k[1] + k[2] * k[2])
        for i in range(4):
            f = 2.0 * coef[h] * weights[h, i]
            v = hinges[h, i]
            for c in range(3):
                grad[v, c] += f * k[c]
    return total


@numba.njit(cache=True)
def stretch_energy(x, edges, rest, soft, limit, limit_strain, grad):  # pragma: no cover - numba
    """Edge stretch energy (see the module docstring) of x (V, 3); adds its gradient to grad (V, 3)."""
    total = 0.0
    for i in range(edges.shape[0]):
        a, b = edges[i, 0], edges[i, 1]
        dx = x[a, 0] - x[b, 0]
        dy = x[a, 1] - x[b, 1]
        dz = x[a, 2] - x[b, 2]
        length = np.sqrt(dx * dx + dy * dy + dz * dz) + 1e-300
        L = rest[i]
        s = length / L - 1.0
        total += L * soft * s * s
        de = 2.0 * L * soft * s
        over = abs(s) - limit_strain
        if over > 0.0:
            total += L * limit * over * over
            de += 2.0 * L * limit * over * (1.0 if s > 0.0 else -1.0)
        f = de / (L * length)
        grad[a, 0] += f * dx
        grad[a, 1] += f * dy
        grad[a, 2] += f * dz
        grad[b, 0] -= f * dx
        grad[b, 1] -= f * dy
        grad[b, 2] -= f * dz
    return total


@numba.njit(cache=True)
def plane_energy(x, index, points, normals, offset, weight, grad):  # pragma: no cover - numba
    """Contact energy: weight max(offset - (x_v - p) . n, 0)^2 per vertex v = index[j] with plane (points[j],
    normals[j]); adds its gradient to grad."""
    total = 0.0
    for j in range(index.shape[0]):
        v = index[j]
        d = 0.0
        for c in range(3):
            d += (x[v, c] - points[j, c]) * normals[j, c]
        depth = offset - d
        if depth > 0.0:
            total += weight * depth * depth
            for c in range(3):
                grad[v, c] -= 2.0 * weight * depth * normals[j, c]
    return total


@numba.njit(cache=True)
def layer_energy(x, vertex, tri, bary, normals, gap, weight, grad):  # pragma: no cover - numba
    """Layer order energy: weight max(gap - (x_v - q) . n, 0)^2 per layered vertex v = vertex[j] with q = sum bary[j]
    x[tri[j]] its nearest point on the other layer's face and n = normals[j] the way it must lie from there; adds
    its gradient (on v and on the face's corners) to grad."""
    total = 0.0
    for j in range(vertex.shape[0]):
        v = vertex[j]
        h = 0.0
        for c in range(3):
            q = bary[j, 0] * x[tri[j, 0], c] + bary[j, 1] * x[tri[j, 1], c] + bary[j, 2] * x[tri[j, 2], c]
            h += (x[v, c] - q) * normals[j, c]
        short = gap - h
        if short > 0.0:
            total += weight * short * short
            f = 2.0 * weight * short
            for c in range(3):
                grad[v, c] -= f * normals[j, c]
                for k in range(3):
                    grad[tri[j, k], c] += f * bary[j, k] * normals[j, c]
    return total


@numba.njit(cache=True)
def tether_energy(x, tri, bary, targets, reach, weight, grad):  # pragma: no cover - numba
    """Tether energy: weight max(|p - q| - reach, 0)^2 per cloth point p = sum bary x[tri] with target q =
    targets[j]; adds its gradient to grad."""
    total = 0.0
    r = np.zeros(3)
    for j in range(tri.shape[0]):
        for c in range(3):
            r[c] = bary[j, 0] * x[tri[j, 0], c] + bary[j, 1] * x[tri[j, 1], c] + bary[j, 2] * x[tri[j, 2], c]
            r[c] -= targets[j, c]
        d = np.sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2])
        if d > reach:
            total += weight * (d - reach) ** 2
            f = 2.0 * weight * (d - reach) / d
            for k in range(3):
                for c in range(3):
                    grad[tri[j, k], c] += f * bary[j, k] * r[c]
    return total


@numba.njit(cache=True)
def polish_energy(x, grad, terms):  # pragma: no cover - numba
    """The polish's energy of x (V, 3): stretch, bending, contact planes, layer order, tethers; grad (V, 3) is
    overwritten with its gradient. terms : the tuple (edges, rest, soft, limit, limit_strain, hinges, bend_weights,
    bend_coef, contact_index, contact_points, contact_normals, offset, contact_weight, layer_vertex, layer_tri,
    layer_bary, layer_normal, layer_gap, layer_weight, tether_tri, tether_bary, tether_targets, reach,
    tether_weight) of the kernels' arguments (empty arrays for an unused term)."""
    (edges, rest, soft, limit, limit_strain, hinges, bend_w, bend_coef, near, points, normals, offset, contact_w,
     layer_v, layer_tri, layer_b, layer_n, layer_gap, layer_w, tether_tri, tether_bary, targets, reach,
     tether_w) = terms  # fmt: skip
    grad[:] = 0.0
    total = stretch_energy(x, edges, rest, soft, limit, limit_strain, grad)
    total += bend_energy(x, hinges, bend_w, bend_coef, grad)
    total += plane_energy(x, near, points, normals, offset, contact_w, grad)
    total += layer_energy(x, layer_v, layer_tri, layer_b, layer_n, layer_gap, layer_w, grad)
    total += tether_energy(x, tether_tri, tether_bary, targets, reach, tether_w, grad)
    return total
