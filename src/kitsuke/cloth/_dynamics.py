"""Dynamic cloth: XPBD with small steps (SPEC §5.4), beside the relaxation — the same `ClothModel` and `ClothState`
(with velocities), one `step(model, state, collider, dt)`.

Each step of `dt` seconds runs `DynamicsParams.substeps` substeps of h = dt / substeps, each:
1. predict: gravity into the velocities, positions moved by h·v (`_dynamics_kernels.predict`);
2. one Gauss-Seidel sweep of stretch constraints (every mesh edge keeps its rest length, compliance
   `stretch_compliance`) and of bending constraints (the two vertices opposite each interior edge keep their flat
   rest distance, compliance `bend_compliance`): XPBD, so stiffness does not depend on h or the sweep count;
3. the strain limit: no edge longer than (1 + `max_strain`) its rest length (silk barely stretches);
4. collision with the moving body's capsules, pushed `contact_offset_m` outside with Coulomb friction; the
   capsules move a substep's share of their frame motion each substep (sub-stepped, so a fast leg does not pass
   through the cloth in one frame);
5. velocities from the positions' change, damped by `damping` per second.
Small steps with one sweep each converge better than few steps with many sweeps (Macklin et al., "Small Steps in
Physics Simulation", 2019), and keep the solver stable at dt = 1/30 s.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import ComputationError, InputError
from . import _dynamics_kernels as K
from ._model import ClothModel, ClothState


@dataclass(frozen=True)
class DynamicsParams:
    """Constants of the dynamic solver, with units and why.

    gravity : m/s².
    density_kg_m2 : mass of the cloth per square metre (kimono silk: 0.06-0.12 kg/m²).
    substeps : substeps per `step` (h = dt / substeps); 20 at dt = 1/30 s is h = 1.7 ms.
    stretch_compliance : m/N of the edge constraints; 0 is inextensible (XPBD's α).
    bend_compliance : m/N of the bending constraints; larger folds more easily (silk drapes).
    max_strain : the strain limit: no edge longer than (1 + this) times its rest length.
    damping : fraction of the velocity lost per second (air and internal friction).
    friction : Coulomb coefficient against the body.
    contact_offset_m : distance kept outside the body's capsules, metres.
    max_speed_m_s : a vertex faster than this after a step means the solver diverged (ComputationError).
    """

    gravity: float = 9.81
    density_kg_m2: float = 0.1
    substeps: int = 20
    stretch_compliance: float = 1e-7
    bend_compliance: float = 1e-3
    max_strain: float = 0.02
    damping: float = 0.5
    friction: float = 0.4
    contact_offset_m: float = 0.004
    max_speed_m_s: float = 50.0

    def __post_init__(self) -> None:
        for name in ("gravity", "density_kg_m2", "stretch_compliance", "bend_compliance", "max_strain", "damping"):
            v = getattr(self, name)
            if not (np.isfinite(v) and v >= 0):
                raise InputError(f"dynamics parameter {name} must be a finite number >= 0, got {v!r}")
        if not self.density_kg_m2 > 0:
            raise InputError("dynamics parameter density_kg_m2 must be positive")
        if int(self.substeps) != self.substeps or self.substeps < 1:
            raise InputError(f"dynamics parameter substeps must be a positive integer, got {self.substeps!r}")


@dataclass
class CapsuleBody:
    """A moving body for the dynamic solver: tapered capsules (`Body.capsule_segments`).

    ends : (n, 2, 3) float64 metres, now. radii : (n, 2) float64 metres. previous : (n, 2, 3) where the ends were at
    the previous step (the capsules sweep from there to `ends` over the substeps).
    """

    ends: np.ndarray
    radii: np.ndarray
    previous: np.ndarray = field(default=None)  # type: ignore[assignment]

    def __post_init__(self) -> None:
        self.ends = np.ascontiguousarray(self.ends, dtype=np.float64).reshape(-1, 2, 3)
        self.radii = np.ascontiguousarray(self.radii, dtype=np.float64).reshape(-1, 2)
        self.previous = self.ends.copy() if self.previous is None else np.asarray(self.previous, np.float64)

    def move_to(self, ends: np.ndarray) -> None:
        """The capsules' ends (n, 2, 3) at the next step."""
        self.previous = self.ends
        self.ends = np.ascontiguousarray(ends, dtype=np.float64).reshape(self.previous.shape)


@dataclass
class DynamicsData:
    """What the solver precomputes from a model: lumped masses and the constraint pairs with their rest lengths."""

    mass: np.ndarray  # (V,) kg
    stretch_pairs: np.ndarray  # (E, 2) int64
    stretch_rest: np.ndarray  # (E,) m
    bend_pairs: np.ndarray  # (H, 2) int64
    bend_rest: np.ndarray  # (H,) m


def dynamics_data(model: ClothModel, params: DynamicsParams) -> DynamicsData:
    """Masses (a third of each triangle's rest area times the density to each corner) and constraints: every
    edge at its rest length, and across each interior edge the two opposite vertices at their distance with the
    two rest triangles unfolded flat."""
    mass = np.zeros(model.n_vertices)
    np.add.at(mass, model.faces.reshape(-1), np.repeat(model.rest_areas * params.density_kg_m2 / 3.0, 3))
    bend_rest = np.zeros(len(model.hinges))
    for k, ((a, b, c, d), (f0, f1)) in enumerate(zip(model.hinges, model.hinge_faces, strict=True)):
        bend_rest[k] = _flat_distance(model, f0, f1, a, b, c, d)
    return DynamicsData(
        mass,
        np.ascontiguousarray(model.edges, dtype=np.int64),
        np.ascontiguousarray(model.rest_lengths, dtype=np.float64),
        np.ascontiguousarray(model.hinges[:, 2:4], dtype=np.int64),
        bend_rest,
    )


def _corner(model: ClothModel, face: int, vertex: int) -> np.ndarray:
    k = int(np.flatnonzero(model.faces[face] == vertex)[0])
    return model.rest_corners[face, k]


def _flat_distance(model: ClothModel, f0: int, f1: int, a: int, b: int, c: int, d: int) -> float:
    """Distance between c (of face f0) and d (of face f1) with both rest triangles laid flat on either side of the
    shared edge a-b (each triangle's own rest shape: a seam's two sides may differ slightly)."""

    def local(face: int, q: int) -> tuple[float, float, float]:
        pa, pb, pq = _corner(model, face, a), _corner(model, face, b), _corner(model, face, q)
        e = pb - pa
        length = float(np.linalg.norm(e))
        along = float((pq - pa) @ e) / length
        r = pq - pa
        across = abs(float(e[0] * r[1] - e[1] * r[0])) / length
        return along, across, length

    s0, h0, _ = local(f0, c)
    s1, h1, _ = local(f1, d)
    return float(np.hypot(s0 - s1, h0 + h1))


def start(state: ClothState) -> None:
    """Give `state` velocities (zero) if it has none: the dynamic solver's state is the relaxation's plus them."""
    if state.velocities is None:
        state.velocities = np.zeros_like(state.positions)


def step(
    model: ClothModel,
    state: ClothState,
    body: CapsuleBody | None,
    dt: float,
    params: DynamicsParams | None = None,
    data: DynamicsData | None = None,
) -> None:
    """Advance `state` by `dt` seconds (in place); `body` moves from its previous ends to its current ones over the
    step. Pinned vertices stay where they are. Raises ComputationError ("dynamics") when a position turns
    non-finite or a vertex moves faster than `max_speed_m_s`."""
    params = params or DynamicsParams()
    if not (np.isfinite(dt) and dt > 0):
        raise InputError(f"dt must be a positive number of seconds, got {dt!r}")
    data = data or dynamics_data(model, params)
    start(state)
    x, v = state.positions, state.velocities
    inv_mass = np.where(state.pinned | (data.mass <= 0), 0.0, 1.0 / np.maximum(data.mass, 1e-300))
    n_sub = int(params.substeps)
    h = dt / n_sub
    keep = max(0.0, 1.0 - params.damping * h)
    p = np.empty_like(x)
    lam_s = np.zeros(len(data.stretch_rest))
    lam_b = np.zeros(len(data.bend_rest))
    for s in range(n_sub):
        K.predict(x, v, inv_mass, params.gravity, h, p)
        lam_s[:] = 0.0
        lam_b[:] = 0.0
        K.solve_distances(p, inv_mass, data.stretch_pairs, data.stretch_rest, params.stretch_compliance / h**2, lam_s)
        K.solve_distances(p, inv_mass, data.bend_pairs, data.bend_rest, params.bend_compliance / h**2, lam_b)
        K.limit_strain(p, inv_mass, data.stretch_pairs, data.stretch_rest, params.max_strain)
        if body is not None and len(body.ends):
            t0, t1 = s / n_sub, (s + 1) / n_sub
            ends = (1.0 - t1) * body.previous + t1 * body.ends
            moved = (t1 - t0) * (body.ends - body.previous)
            K.collide_capsules(p, x, inv_mass, ends, body.radii, moved, params.contact_offset_m, params.friction)
        K.finish(x, v, p, inv_mass, h, keep)
    if not np.isfinite(x).all():
        raise ComputationError("dynamics", "cloth positions became non-finite", result=state)
    speed = float(np.sqrt((v * v).sum(axis=1)).max()) if len(v) else 0.0
    if speed > params.max_speed_m_s:
        raise ComputationError("dynamics", f"a vertex moves at {speed:.0f} m/s (diverged)", result=state)
