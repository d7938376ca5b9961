"""Dynamic cloth: XPBD with small steps (SPEC §5.4), beside the relaxation — the same `ClothModel` and `ClothState`
(with velocities), one `step(model, state, collider, dt)`.

Each step of `dt` seconds runs `DynamicsParams.substeps` substeps of h = dt / substeps, each:
1. predict: gravity into the velocities, positions moved by h·v (`_dynamics_kernels.predict`);
2. `sweeps` Gauss-Seidel sweeps of stretch constraints (every mesh edge keeps its rest length, compliance
   `stretch_compliance`) and one of bending constraints (the two vertices opposite each interior edge keep their
   flat rest distance, compliance `bend_compliance`), colour by colour (`K.colour_pairs`): XPBD, so stiffness does
   not depend on h or the sweep count;
3. `contact_rounds` rounds of: collision with the moving body's capsules, pushed `contact_offset_m` outside with
   Coulomb friction (the capsules move a substep's share of their frame motion each substep: sub-stepped, so a
   fast leg does not pass through the cloth in one frame), then the strain limit: no edge longer than
   (1 + `max_strain`) its rest length, nor shorter than (1 - `max_squeeze`). Where the two conflict (a leg beyond
   the reach of the cloth around it, cloth caught between arm and chest) the cloth ends the substep a little way
   into the body rather than torn;
4. velocities from the positions' change, damped by `damping` per second;
5. with a skin (`MovingBody.surface`): in each round of 3, each cloth vertex near the skin stays outside the plane
   of its tracked skin point (moving with the skin over the step, with friction); at the last substep `collide`
   (layer order, capsules, the skin, the floor) moves the cloth out onto the skin and refreshes the tracking,
   the strain limit runs once more, and only the motion into the skin is taken out of the velocities.
Vertices held to the skin (`SkinHold`: a kimono's waist in its obi) move with it, a substep's share at a time.
Small steps with one sweep each converge better than few steps with many sweeps (Macklin et al., "Small Steps in
Physics Simulation", 2019), and keep the solver stable at dt = 1/30 s.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import ComputationError, InputError, require_non_negative
from . import _dynamics_kernels as K
from ._collide import BodyCollider, collide, track
from ._model import ClothModel, ClothState

#: Within a substep, the collision's rounds test only the (cloth vertex, capsule) pairs closer than this many
#: metres (plus the offset) at the substep's start (`K.capsule_candidates`): a round moves cloth millimetres, and
#: testing every vertex against every capsule in every round was a seventh of the kimono's step.
CAPSULE_REACH_M = 0.02
#: The pairs are found once every this many substeps, the reach widened by what the capsules and each cloth vertex
#: (at its speed) can move in the substeps after the first (the search was 8 % of the kimono's step run each one;
#: the walk's frames are the same bit for bit).
CAPSULE_WINDOW = 4


@dataclass(frozen=True)
class DynamicsParams:
    """Constants of the dynamic solver, with units and why.

    gravity : m/s².
    density_kg_m2 : mass of the cloth per square metre (kimono silk: 0.06-0.12 kg/m²).
    substeps : substeps per `step` (h = dt / substeps); 20 at dt = 1/30 s is h = 1.7 ms.
    sweeps : Gauss-Seidel sweeps of the stretch constraints per substep.
    stretch_compliance : m/N of an edge longer than its rest length; 0 is inextensible (XPBD's α).
    compression_compliance : m/N of an edge shorter than its rest length; larger lets cloth buckle instead of
        pushing back.
    bend_compliance : m/N of the bending constraints; larger folds more easily. A vertex of 2 cm silk weighs 40 mg
        (0.4 mN): at 1 m/N a 1 mm bend pushes back with 1 mN, so silk drapes.
    max_squeeze : nor shorter than (1 - this) times it: cloth squeezed more than its mesh can fold (the shoulders'
        skin shortens as the arms come down) buckles out of its plane instead (the walking kimono's median worst
        edge 63 -> 31 % over 40 frames).
    contact_rounds : rounds of collision then strain limit per substep. The strain limit comes last, so that a
        body the cloth cannot make room for pushes into it rather than tearing it; more rounds let the cloth carry
        the push further. A tube around a leg jumping up to 25 cm a frame, over 1,000 frames, seeds 3-7: the leg
        more than 2 mm through it in 1-2 % of the frames (up to 4 cm at worst), edges up to 0.6-1.4 times longer;
        with collision last it was never through, and its edges stretched to 4.7 times their length.
    max_strain : the strain limit: no edge longer than (1 + this) times its rest length (silk barely stretches).
        A dressed garment can start above it (the dressing's target is 5 %): `dynamics_data(..., start=)` then
        lengthens those edges' rest lengths, so that the first step does not snap the garment shorter.
    damping : fraction of the velocity lost per second (air and internal friction).
    friction : Coulomb coefficient against the body.
    contact_offset_m : distance kept outside the body's capsules, metres.
    max_speed_m_s : a vertex that moved faster than this over a step (its move over the step / dt) means the
        solver diverged (ComputationError). Over the step, not its last substep: a collision's push within one
        substep is a brief velocity, not a divergence (a sleeve whipped by the hand in the CMU walk at 120 fps: 63
        m/s in its last substep, 18 m/s over the frame, and calm again a few frames later).
    """

    gravity: float = 9.81
    density_kg_m2: float = 0.1
    substeps: int = 20
    sweeps: int = 2
    stretch_compliance: float = 1e-7
    compression_compliance: float = 1e-7
    bend_compliance: float = 1.0
    max_strain: float = 0.02
    max_squeeze: float = 0.20
    contact_rounds: int = 4
    damping: float = 0.5
    friction: float = 0.4
    contact_offset_m: float = 0.004
    max_speed_m_s: float = 50.0

    def __post_init__(self) -> None:
        require_non_negative(
            self,
            "dynamics parameter",
            "gravity",
            "density_kg_m2",
            "stretch_compliance",
            "compression_compliance",
            "bend_compliance",
            "max_strain",
            "max_squeeze",
            "damping",
        )
        if not self.density_kg_m2 > 0:
            raise InputError("dynamics parameter density_kg_m2 must be positive")
        for name in ("substeps", "sweeps", "contact_rounds"):
            v = getattr(self, name)
            if int(v) != v or v < 1:
                raise InputError(f"dynamics parameter {name} must be a positive integer, got {v!r}")


@dataclass
class SkinHold:
    """Cloth vertices held at points of the skin, following the body (a kimono's waist in its obi).

    vertices : (k,) int64 cloth vertices. faces : (k,) int64 skin triangles. bary : (k, 3) float64 barycentric
    coordinates on them. offset : (k,) float64 metres along the skin's normal there.
    rest : (k, 3) the held vertices where they were held, and rest_skin : (k, 3) their skin points then, or None:
    then the band moves rigidly, by the rotation and translation that best carry the skin points to where they
    are now (an obi is stiff: held to each skin point, its edges stretched up to 50 % with the skin of a
    walking waist).
    """

    vertices: np.ndarray
    faces: np.ndarray
    bary: np.ndarray
    offset: np.ndarray
    rest: np.ndarray | None = None
    rest_skin: np.ndarray | None = None

    @classmethod
    def band(
        cls,
        positions: np.ndarray,
        skin: BodyCollider,
        low: float,
        high: float,
        *,
        on_faces: np.ndarray | None = None,
        max_distance_m: float = 0.03,
        rigid: bool = True,
    ) -> SkinHold:
        """Hold the cloth vertices (V, 3) whose height is within [low, high] metres and that lie within
        `max_distance_m` of the skin `skin`, where they are now (an obi from `kitsuke.dressing.kimono.obi_band`: it
        ties what lies on the waist, not a sleeve hanging beside it). on_faces : (Fb,) bool, the skin triangles
        that may hold (the trunk's: a sleeve beside the waist is nearest the arm, which must not drag it).
        rigid : the band moves as one rigid piece with its skin points (see the class), else each vertex with its
        own skin point."""
        idx = np.flatnonzero((positions[:, 1] >= low) & (positions[:, 1] <= high))
        if len(idx):
            face, _, dist = skin.nearest(positions[idx])
            keep = dist <= max_distance_m
            if on_faces is not None:
                keep &= on_faces[face]
            idx = idx[keep]
        if len(idx) == 0:
            return cls(idx, idx.copy(), np.zeros((0, 3)), np.zeros(0))
        face, point, _ = skin.nearest(positions[idx])
        tri = skin.vertices[skin.faces[face]]
        bary = _barycentric(point, tri)
        offset = ((positions[idx] - point) * skin.face_normals[face]).sum(axis=1)
        held = cls(idx.astype(np.int64), face.astype(np.int64), bary, offset)
        if rigid:
            held.rest, held.rest_skin = positions[idx].copy(), held.skin_points(skin)
        return held

    def skin_points(self, skin: BodyCollider) -> np.ndarray:
        """(k, 3) the held vertices' skin points on `skin`."""
        return np.einsum("kc,kcd->kd", self.bary, skin.vertices[skin.faces[self.faces]])

    def targets(self, skin: BodyCollider) -> np.ndarray:
        """(k, 3) where the held vertices belong on `skin` (the same topology, any pose)."""
        points = self.skin_points(skin)
        if self.rest is not None:
            a, b = self.rest_skin - self.rest_skin.mean(axis=0), points - points.mean(axis=0)
            u, _, vt = np.linalg.svd(b.T @ a)
            r = u @ np.diag([1.0, 1.0, np.sign(np.linalg.det(u @ vt)) or 1.0]) @ vt
            return (self.rest - self.rest_skin.mean(axis=0)) @ r.T + points.mean(axis=0)
        return points + self.offset[:, None] * skin.face_normals[self.faces]


def _barycentric(p: np.ndarray, tri: np.ndarray) -> np.ndarray:
    """(k, 3) barycentric coordinates of points p (k, 3) on triangles (k, 3, 3) (the points lie on them)."""
    e1, e2, d = tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0], p - tri[:, 0]
    d11, d12, d22 = (e1 * e1).sum(1), (e1 * e2).sum(1), (e2 * e2).sum(1)
    d1, d2 = (d * e1).sum(1), (d * e2).sum(1)
    den = np.maximum(d11 * d22 - d12 * d12, 1e-300)
    b1 = (d22 * d1 - d12 * d2) / den
    b2 = (d11 * d2 - d12 * d1) / den
    return np.column_stack([1.0 - b1 - b2, b1, b2])


@dataclass
class MovingBody:
    """A moving body for the dynamic solver: its tapered capsules (`Body.capsule_segments`), and optionally its skin

    ends : (n, 2, 3) float64 metres, now. radii : (n, 2) float64 metres. previous : (n, 2, 3) where the ends were at
    the previous step (the capsules sweep from there to `ends` over the substeps).
    surface : the body's skin at this step (a `BodyCollider`, with the same capsules) or None. The capsules are
    inscribed in the limbs; the skin is what cloth rests on. It is collided with once a step, at its last substep
    (`collide`: layer order, capsules, the surface, the floor), after the capsules kept fast limbs from passing
    through the cloth during the step.
    """

    ends: np.ndarray
    radii: np.ndarray
    previous: np.ndarray = field(default=None)  # type: ignore[assignment]
    surface: BodyCollider | None = None
    hold: SkinHold | None = None
    hold_previous: np.ndarray | None = None
    hold_now: np.ndarray | None = None
    skin_previous: np.ndarray | None = None

    def __post_init__(self) -> None:
        self.ends = np.ascontiguousarray(self.ends, dtype=np.float64).reshape(-1, 2, 3)
        self.radii = np.ascontiguousarray(self.radii, dtype=np.float64).reshape(-1, 2)
        self.previous = self.ends.copy() if self.previous is None else np.asarray(self.previous, np.float64)

    @classmethod
    def of(cls, collider: BodyCollider) -> MovingBody:
        """The moving body of a collider (`BodyCollider.from_body`): its capsules and its skin."""
        return cls(collider.capsule_ends, collider.capsule_radii, surface=collider)

    def move_to(self, ends: np.ndarray, vertices: np.ndarray | None = None) -> None:
        """The capsules' ends (n, 2, 3) at the next step, and the skin's vertices (Vb, 3) if it has one."""
        self.previous = self.ends
        self.ends = np.ascontiguousarray(ends, dtype=np.float64).reshape(self.previous.shape)
        if self.surface is not None:
            if vertices is None:
                raise InputError("this body has a skin: give its vertices with the capsules")
            self.skin_previous = self.surface.vertices
            self.surface = self.surface.moved(vertices, self.ends)
            if self.hold is not None:
                self.hold_previous = self.hold_now
                self.hold_now = self.hold.targets(self.surface)

    def hold_band(self, positions: np.ndarray, low: float, high: float, on_faces: np.ndarray | None = None) -> SkinHold:
        """Hold the cloth's vertices (V, 3) within [low, high] metres of height to the skin from now on
        (`SkinHold.band`)."""
        if self.surface is None:
            raise InputError("holding cloth to the skin needs a body with a skin (MovingBody.of)")
        self.hold = SkinHold.band(positions, self.surface, low, high, on_faces=on_faces)
        self.hold_now = self.hold.targets(self.surface)
        self.hold_previous = self.hold_now
        return self.hold


@dataclass
class DynamicsData:
    """What the solver precomputes from a model: lumped masses and the constraint pairs with their rest lengths,
    in the order the sweeps take them (colour by colour: `K.colour_pairs`)."""

    mass: np.ndarray  # (V,) kg
    stretch_pairs: np.ndarray  # (E, 2) int64
    stretch_rest: np.ndarray  # (E,) m
    bend_pairs: np.ndarray  # (H, 2) int64
    bend_rest: np.ndarray  # (H,) m
    stretch_edge: np.ndarray  # (E,) int64: the model's edge of each stretch pair


def dynamics_data(model: ClothModel, params: DynamicsParams, start: np.ndarray | None = None) -> DynamicsData:
    """Masses (a third of each triangle's rest area times the density to each corner) and constraints: every
    edge at its rest length, and across each interior edge the two opposite vertices at their distance with the
    two rest triangles unfolded flat.

    start : (V, 3) the positions the simulation starts from (a dressed garment), or None: an edge stretched
    beyond the strain limit there gets the rest length that puts it at the limit, and an edge shorter than its
    rest length (a fold the dressing pressed, down to −4.9 % on the demo's kimono) its length there, so that the
    first step does not snap the garment (held to the pattern's lengths, the kimono's hems moved 2-5 cm in it).
    The bending constraints then keep the garment's folds as they are at the start, not flat: a kimono is pressed
    along its folds (shoulders, sleeves, the collar), and pushing 180° folds open tore it within a step.
    """
    mass = np.zeros(model.n_vertices)
    np.add.at(mass, model.faces.reshape(-1), np.repeat(model.rest_areas * params.density_kg_m2 / 3.0, 3))
    rest = np.array(model.rest_lengths, dtype=np.float64)
    hinge = model.hinges[:, 2:4]
    if start is None:
        bend_rest = np.array(
            [
                _flat_distance(model, f0, f1, a, b, c, d)
                for (a, b, c, d), (f0, f1) in zip(model.hinges, model.hinge_faces, strict=True)
            ]
        ).reshape(-1)
    else:
        now = np.linalg.norm(start[model.edges[:, 1]] - start[model.edges[:, 0]], axis=1)
        rest = np.maximum(np.minimum(rest, now), now / (1.0 + params.max_strain))
        bend_rest = np.linalg.norm(start[hinge[:, 1]] - start[hinge[:, 0]], axis=1)
    stretch = _by_colour(np.ascontiguousarray(model.edges, dtype=np.int64), model.n_vertices)
    bend = _by_colour(np.ascontiguousarray(hinge, dtype=np.int64), model.n_vertices)
    return DynamicsData(
        mass,
        np.ascontiguousarray(model.edges[stretch]),
        np.ascontiguousarray(rest[stretch]),
        np.ascontiguousarray(hinge[bend]),
        np.ascontiguousarray(bend_rest[bend]),
        stretch.astype(np.int64),
    )


def _by_colour(pairs: np.ndarray, n_vertices: int) -> np.ndarray:
    """The order (K,) that sweeps the pairs colour by colour (`K.colour_pairs`), each colour in its own order."""
    return np.argsort(K.colour_pairs(pairs, n_vertices), kind="stable")


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


def _absorb_push(x: np.ndarray, v: np.ndarray, push: np.ndarray) -> None:
    """Apply the skin's push-out to the positions without turning it into speed (the skin moves once a step, so a
    push can be centimetres: as a velocity it would fling the cloth off), and stop what still moved into it."""
    length = np.linalg.norm(push, axis=1)
    hit = length > 0
    if not hit.any():
        return
    n = push[hit] / length[hit, None]
    into = np.minimum((v[hit] * n).sum(axis=1), 0.0)
    v[hit] -= into[:, None] * n
    x[hit] += push[hit]


def _skin_planes(model: ClothModel, state: ClothState, body: MovingBody):
    """The skin under each cloth vertex tracked near it by the last collision, as planes for every substep: (index
    (k,), point at the step's start (k, 3), point at its end (k, 3), unit normal at its end (k, 3)), or None. The
    full collision runs once a step; without these planes the weight of a garment hanging from the shoulders
    sank it a centimetre and more into them within a step (pushed back at its end, it flew off)."""
    c = state.contacts
    if not (c.face >= 0).any():  # the first step: find the skin under the cloth
        track(model, state, body.surface)
    reach = 4.0 * model.params.contact_distance_m
    index = np.flatnonzero((c.face >= 0) & (c.distance < reach))
    if len(index) == 0:
        return None
    skin = body.surface
    faces = skin.faces[c.face[index]]
    bary = c.bary[index]
    end = np.einsum("kc,kcd->kd", bary, skin.vertices[faces])
    before = skin.vertices if body.skin_previous is None else body.skin_previous
    start = np.einsum("kc,kcd->kd", bary, before[faces])
    normals = np.ascontiguousarray(skin.face_normals[c.face[index]])
    return index.astype(np.int64), np.ascontiguousarray(start), np.ascontiguousarray(end), normals


def _collide_surface(model: ClothModel, state: ClothState, p: np.ndarray, surface: BodyCollider) -> None:
    """`collide` on the predicted positions p (in place): the state's contacts keep tracking the skin."""
    x = state.positions
    state.positions = p
    try:
        collide(model, state, surface)
    finally:
        state.positions = x


def step(
    model: ClothModel,
    state: ClothState,
    body: MovingBody | None,
    dt: float,
    params: DynamicsParams | None = None,
    data: DynamicsData | None = None,
) -> None:
    """Advance `state` by `dt` seconds (in place); `body` moves from its previous ends to its current ones over the
    step. Pinned vertices stay where they are. Raises ComputationError ("dynamics") when a position turns
    non-finite or a vertex moves faster than `max_speed_m_s` over the step."""
    params = params or DynamicsParams()
    if not (np.isfinite(dt) and dt > 0):
        raise InputError(f"dt must be a positive number of seconds, got {dt!r}")
    data = data or dynamics_data(model, params)
    start(state)
    x, v = state.positions, state.velocities
    x_start = x.copy()
    held = body.hold if body is not None and body.hold is not None and len(body.hold.vertices) else None
    fixed = state.pinned | (data.mass <= 0)
    if held is not None:
        fixed = fixed.copy()
        fixed[held.vertices] = True
    inv_mass = np.where(fixed, 0.0, 1.0 / np.maximum(data.mass, 1e-300))
    n_sub = int(params.substeps)
    h = dt / n_sub
    keep = max(0.0, 1.0 - params.damping * h)
    planes = _skin_planes(model, state, body) if body is not None and body.surface is not None else None
    p = np.empty_like(x)
    capsules = body is not None and len(body.ends) > 0
    pairs = np.empty((len(x) * len(body.ends) if capsules else 0, 2), dtype=np.int64)
    lam_s = np.zeros(len(data.stretch_rest))
    lam_b = np.zeros(len(data.bend_rest))
    w_s = inv_mass[data.stretch_pairs[:, 0]] + inv_mass[data.stretch_pairs[:, 1]]
    w_b = inv_mass[data.bend_pairs[:, 0]] + inv_mass[data.bend_pairs[:, 1]]
    # how far each capsule's farther end moves in a substep (no point of its axis moves farther)
    capsule_move = np.sqrt(((body.ends - body.previous) ** 2).sum(axis=2)).max(axis=1) / n_sub if capsules else None
    for s in range(n_sub):
        if held is not None:  # held vertices move with the skin, a substep's share of the step at a time
            t1 = (s + 1) / n_sub
            x[held.vertices] = (1.0 - t1) * body.hold_previous + t1 * body.hold_now
        K.predict(x, v, inv_mass, params.gravity, h, p)
        lam_s[:] = 0.0
        lam_b[:] = 0.0
        stretch, short = params.stretch_compliance / h**2, params.compression_compliance / h**2
        for _ in range(int(params.sweeps)):
            K.solve_distances(p, inv_mass, data.stretch_pairs, data.stretch_rest, w_s, stretch, short, lam_s)
        bend = params.bend_compliance / h**2
        K.solve_distances(p, inv_mass, data.bend_pairs, data.bend_rest, w_b, bend, bend, lam_b)
        t0, t1 = s / n_sub, (s + 1) / n_sub
        if capsules:  # what is fixed over the substep, once
            ends = (1.0 - t1) * body.previous + t1 * body.ends
            moved = (t1 - t0) * (body.ends - body.previous)
            if s % CAPSULE_WINDOW == 0:
                ahead = min(CAPSULE_WINDOW, n_sub - s) - 1  # substeps the pairs serve after this one
                reach = params.contact_offset_m + CAPSULE_REACH_M + ahead * capsule_move
                n_pairs = K.capsule_candidates(p, inv_mass, ends, body.radii, reach, v, ahead * h, pairs)
        if planes is not None:
            index, plane_start, plane_end, normals = planes
            points = (1.0 - t1) * plane_start + t1 * plane_end
            plane_moved = (t1 - t0) * (plane_end - plane_start)
        for _ in range(int(params.contact_rounds)):
            if capsules:
                K.collide_capsule_pairs(p, x, ends, body.radii, moved, params.contact_offset_m, params.friction, pairs,
                                        n_pairs)  # fmt: skip
            if planes is not None:
                K.collide_planes(p, x, inv_mass, index, points, normals, plane_moved, model.params.contact_offset_m,
                                 params.friction)  # fmt: skip
            K.limit_strain(p, inv_mass, data.stretch_pairs, data.stretch_rest, params.max_strain, params.max_squeeze)
        if body is not None and body.surface is not None and s == n_sub - 1:
            before = p.copy()
            _collide_surface(model, state, p, body.surface)
            if held is not None:  # the obi holds them where the skin puts them, whatever lies around
                p[held.vertices] = before[held.vertices]
            # the skin's push can stretch what it moves: the limit once more (the walking kimono's worst edge
            # 1.8 -> 0.47 strain over 40 frames)
            K.limit_strain(p, inv_mass, data.stretch_pairs, data.stretch_rest, params.max_strain, params.max_squeeze)
            K.finish(x, v, before, inv_mass, h, keep)
            _absorb_push(x, v, p - before)
            continue
        K.finish(x, v, p, inv_mass, h, keep)
    if not np.isfinite(x).all():
        raise ComputationError("dynamics", "cloth positions became non-finite", result=state)
    moved = float(np.sqrt(((x - x_start) ** 2).sum(axis=1)).max()) if len(x) else 0.0
    if moved > params.max_speed_m_s * dt:
        raise ComputationError(
            "dynamics", f"a vertex moved {moved:.2f} m in one step ({moved / dt:.0f} m/s: diverged)", result=state
        )
