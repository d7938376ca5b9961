"""Benchmark: the kimono simulated on a walking body by kitsuke's solver and by NVIDIA newton (CPU), same run.

    python benchmarks/bench_newton_kimono.py --frames 60 --json out.json

What it measures, for each tool on the same frames (the lead-in from the rest pose, then --frames clip frames of the
corrected CMU walk 131_01 at stride 4, 30 fps, as `kitsuke.tryon.simulate_kimono` runs it):
- wall time per simulated frame (dt = 1/30 s), the first frame apart: it pays numba's or warp's one-time kernel
  compilation, which is reported on its own (newton compiles into an empty cache unless --warp-cache is given);
- per frame, with kitsuke's own measures: cloth vertices more than 5 mm inside the posed skin (winding number,
  `kitsuke.metrics.penetration`) and edge strain against the pattern's rest lengths (`kitsuke.metrics.strain`),
  summarised over the clip frames: frames within targets (none > 5 mm inside and max strain <= 10 %), median and
  worst max strain, median and worst 99th-percentile strain, worst penetration count and depth.

The same cloth for both: the 5,100-vertex kimono dressed for simulation (`default_simulation_kimono`), its
triangles, its lumped masses (0.1 kg/m²) and the rest edge lengths kitsuke's solver starts from (the pattern's,
adjusted where the dressing left an edge shorter or more than 2 % longer: `dynamics_data(..., start=)`; newton
gets each triangle's rest shape from those three lengths). The same body motion for both: the default body skinned
per frame (not timed for either), its tapered capsules, and the obi band's held vertices moved kinematically onto
their targets (`SkinHold`), a substep's share at a time.

newton's side (defaults: VBD, 20 substeps x 2 iterations, as kitsuke's 20 substeps x 2 sweeps): the body is what
kitsuke's solver collides with, capsules and skin. Each of the 10 tapered capsules is a kinematic body carrying
--capsule-pieces plain capsules (newton has none tapered) of the taper's radius at each piece's middle; the skin is
a mesh shape whose vertices (and velocities, for friction) we move and refit every substep; the floor is a ground
plane. Everything moves linearly over a frame's substeps. VBD runs with the rigid bodies integrated "externally"
(by us: start pose in the input state, end pose in the output state). XPBD (--solver xpbd: springs on every edge
and across every hinge) diverges on this cloth unless its springs are ~1 N/m (it sums its Jacobi corrections
and a vertex weighs ~10 mg), far softer than silk. Self-contact is off in newton (kitsuke orders its layers at
each frame's end instead). newton is not a kitsuke dependency: `pip install newton==1.8.0 warp-lang==1.19.0`;
without it the kitsuke half still runs. Takes about 3 minutes on 2 cores (newton: ~50 s of kernel compilation,
then ~1 s per frame; warp runs its CPU kernels on one thread).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
BVH = ROOT / "tests/data/pose/cmu_131_01_start_walk_stop.bvh"
INSTALL_HINT = "pip install newton==1.8.0 warp-lang==1.19.0"


# --------------------------------------------------------------------------------------------------------------
# The scene both tools simulate
# --------------------------------------------------------------------------------------------------------------


@dataclass
class Scene:
    """The dressed kimono, the body's motion and what both tools are measured against.

    positions : (V, 3) the dressed kimono. faces : (F, 3). edges, rest_pattern : the cloth's edges and the pattern's
    rest lengths (what strain is measured against). rest_start : the rest lengths kitsuke's solver starts from.
    mass : (V,) kg. held : (k,) the obi band's vertices. skin : (n, Vb, 3) the posed skin per frame. body_faces :
    (Fb, 3). ends : (n, C, 2, 3) capsule ends per frame (ends_rest (C, 2, 3) at rest), radii : (C, 2).
    hold : (n, k, 3) the held vertices' targets per frame (hold_rest (k, 3) at rest). floor_y : metres.
    n_lead : lead-in frames. dt : seconds per frame.
    """

    garment: object
    body: object
    weights: np.ndarray
    positions: np.ndarray
    faces: np.ndarray
    edges: np.ndarray
    rest_pattern: np.ndarray
    rest_start: np.ndarray
    mass: np.ndarray
    held: np.ndarray
    skin: np.ndarray
    body_faces: np.ndarray
    ends: np.ndarray
    ends_rest: np.ndarray
    radii: np.ndarray
    hold: np.ndarray
    hold_rest: np.ndarray
    floor_y: float
    n_lead: int
    dt: float

    @property
    def n_frames(self) -> int:
        return len(self.skin)


def _animation(body, frames: int):  # noqa: ANN001, ANN202
    """The corrected walk with its lead-in from the rest pose, as `simulate_kimono` runs it by default."""
    from kitsuke.body.animate import animate
    from kitsuke.pose import correct_poses, load_bvh
    from kitsuke.tryon import SimulationSettings
    from kitsuke.tryon.motion import with_lead_in

    s = SimulationSettings()
    poses = correct_poses(load_bvh(BVH, stride=4, max_frames=frames)).poses
    return with_lead_in(animate(body, poses), body.rig.joints, hold_s=s.hold_s, blend_s=s.blend_s)


def build_scene(frames: int) -> Scene:
    """Dress the kimono on the default body and pose the body over the walk (skin, capsules, obi targets)."""
    from kitsuke.body import default_body
    from kitsuke.body.capsules import capsule_segments
    from kitsuke.body.skinning import skin
    from kitsuke.dressing.export import as_garment_file
    from kitsuke.tryon import KimonoSimulator, default_simulation_kimono

    body = default_body()
    animation, n_lead = _animation(body, frames)
    garment = default_simulation_kimono(body)
    sim = KimonoSimulator(body, garment, animation.weights)  # its obi hold and masses; it is not stepped
    g = as_garment_file(garment)
    moving, rig = sim.moving, body.rig
    ends_rest = moving.ends.copy()
    hold_rest = moving.hold_now.copy()
    skins, ends, holds = [], [], []
    for f in range(animation.n_frames):
        v = skin(body.mesh.vertices, animation.weights, rig.joints, animation.rotations[f], animation.joints[f])
        e, _ = capsule_segments(body.capsules, animation.joints[f], animation.rotations[f])
        moving.move_to(e, v)
        skins.append(v)
        ends.append(e)
        holds.append(moving.hold_now.copy())
    return Scene(
        garment=garment,
        body=body,
        weights=animation.weights,
        positions=np.asarray(g.positions, dtype=np.float64),
        faces=np.asarray(g.faces, dtype=np.int64),
        edges=sim.model.edges,
        rest_pattern=np.asarray(sim.model.rest_lengths, dtype=np.float64),
        rest_start=_in_model_order(sim.data.stretch_rest, sim.data.stretch_edge),
        mass=sim.data.mass.copy(),
        held=moving.hold.vertices.copy(),
        skin=np.asarray(skins),
        body_faces=body.mesh.faces,
        ends=np.asarray(ends),
        ends_rest=ends_rest,
        radii=moving.radii.copy(),
        hold=np.asarray(holds),
        hold_rest=hold_rest,
        floor_y=float(body.mesh.vertices[:, 1].min()),
        n_lead=n_lead,
        dt=1.0 / animation.fps,
    )


def _in_model_order(values: np.ndarray, edge: np.ndarray) -> np.ndarray:
    """Per-pair values of kitsuke's solver (in its sweeps' order) in the order of the model's edges."""
    out = np.empty_like(values)
    out[edge] = values
    return out


# --------------------------------------------------------------------------------------------------------------
# Measuring
# --------------------------------------------------------------------------------------------------------------


def measure(scene: Scene, frame: int, positions: np.ndarray, step_s: float) -> dict:
    """One frame's measures, with kitsuke's functions and the motion targets (5 mm inside, 10 % strain)."""
    from kitsuke.geometry import TriMesh
    from kitsuke.metrics import QualityTargets, penetration, strain

    t = QualityTargets.motion()
    x = np.asarray(positions, dtype=np.float64)
    if not np.isfinite(x).all():
        return {"frame": frame, "lead_in": frame < scene.n_lead, "step_s": step_s, "diverged": True, "ok": False}
    pen = penetration(x, TriMesh(scene.skin[frame], scene.body_faces), threshold_m=t.penetration_mm / 1e3)
    s = strain(x, scene.edges, scene.rest_pattern)
    free = np.delete(pen.depth_m, scene.held)  # the cloth the solver moves (the obi's vertices are put in place)
    return {
        "frame": frame,
        "lead_in": frame < scene.n_lead,
        "step_s": round(step_s, 5),
        "penetration_count": pen.count,
        "penetration_deepest_mm": round(pen.deepest_mm, 2),
        "penetration_free_count": int((free > t.penetration_mm / 1e3).sum()),
        "penetration_free_deepest_mm": round(float(free.max(initial=0.0)) * 1e3, 2),
        "strain_max": round(s.max, 5),
        "strain_p99": round(float(np.percentile(s.per_edge, 99)), 5),
        "strain_mean": round(s.mean, 6),
        "ok": pen.count == 0 and s.max <= t.max_strain,
    }


def start_quality(scene: Scene) -> dict:
    """The dressed kimono's own measures on the rest body, before any step: what both tools start from (its
    strain against the pattern is already over the 10 % target on some edges, pressed folds)."""
    from kitsuke.geometry import TriMesh
    from kitsuke.metrics import penetration, strain

    pen = penetration(scene.positions, TriMesh(scene.body.mesh.vertices, scene.body_faces), threshold_m=0.005)
    s = strain(scene.positions, scene.edges, scene.rest_pattern)
    return {
        "penetration_count": pen.count,
        "penetration_deepest_mm": round(pen.deepest_mm, 2),
        "strain_max": round(s.max, 5),
        "strain_p99": round(float(np.percentile(s.per_edge, 99)), 5),
        "edges_over_10_percent": int((s.per_edge > 0.10).sum()),
        "edges": len(scene.edges),
    }


def summarise(scene: Scene, per_frame: list[dict], extra: dict) -> dict:
    """Time per frame (the first apart) and the quality over the clip frames (the lead-in apart)."""
    steps = np.array([q["step_s"] for q in per_frame])
    clip = [q for q in per_frame if not q["lead_in"] and not q.get("diverged")]
    diverged = [q["frame"] for q in per_frame if q.get("diverged")]
    out = {
        **extra,
        "frames": len(per_frame),
        "lead_in_frames": scene.n_lead,
        "clip_frames": sum(not q["lead_in"] for q in per_frame),
        "first_frame_s": round(float(steps[0]), 3),
        "frame_s_median": round(float(np.median(steps[1:])), 4) if len(steps) > 1 else None,
        "frame_s_mean": round(float(np.mean(steps[1:])), 4) if len(steps) > 1 else None,
        "diverged_at_frame": diverged[0] if diverged else None,
        "frames_within_targets": sum(q["ok"] for q in clip),
    }
    if clip:
        smax = np.array([q["strain_max"] for q in clip])
        p99 = np.array([q["strain_p99"] for q in clip])
        out |= {
            "strain_max_median": round(float(np.median(smax)), 4),
            "strain_max_worst": round(float(smax.max()), 4),
            "strain_p99_median": round(float(np.median(p99)), 4),
            "strain_p99_worst": round(float(p99.max()), 4),
            "penetration_count_worst": max(q["penetration_count"] for q in clip),
            "penetration_deepest_mm": max(q["penetration_deepest_mm"] for q in clip),
            "frames_with_penetration": sum(q["penetration_count"] > 0 for q in clip),
            "penetration_free_count_worst": max(q["penetration_free_count"] for q in clip),
            "penetration_free_deepest_mm": max(q["penetration_free_deepest_mm"] for q in clip),
        }
    out["per_frame"] = per_frame
    return out


# --------------------------------------------------------------------------------------------------------------
# kitsuke
# --------------------------------------------------------------------------------------------------------------


def run_kitsuke(scene: Scene) -> dict:
    """kitsuke's XPBD (`KimonoSimulator` with the default `DynamicsParams`); timed per frame: the moving body's
    update (capsules, skin collider, obi targets) and the step, the skinning apart (it is shared)."""
    from kitsuke.cloth import step
    from kitsuke.tryon import KimonoSimulator

    sim = KimonoSimulator(scene.body, scene.garment, scene.weights)
    p = sim.settings.dynamics
    per_frame = []
    for f in range(scene.n_frames):
        t0 = time.perf_counter()
        sim.moving.move_to(scene.ends[f], scene.skin[f])
        step(sim.model, sim.state, sim.moving, scene.dt, p, sim.data)
        took = time.perf_counter() - t0
        per_frame.append(measure(scene, f, sim.state.positions, took))
    squeeze = getattr(p, "max_squeeze", None)
    limits = f"{100 * p.max_strain:g} % stretch" + (f" / {100 * squeeze:g} % squeeze" if squeeze is not None else "")
    settings = (
        f"XPBD, {p.substeps} substeps x ({p.sweeps} stretch sweeps, 1 bending, {p.contact_rounds} rounds of capsules "
        f"+ skin planes + {limits} limit), skin collision once a frame"
    )
    return summarise(scene, per_frame, {"tool": "kitsuke", "solver": settings})


# --------------------------------------------------------------------------------------------------------------
# newton
# --------------------------------------------------------------------------------------------------------------


def _rest_triangles(scene: Scene) -> tuple[np.ndarray, np.ndarray]:
    """Each face's 2x2 rest matrix in newton's convention ([[a, x], [0, y]]: edge 0-1 along the first axis) and
    its area, from kitsuke's starting rest lengths of its three edges."""
    key = {(int(min(a, b)), int(max(a, b))): k for k, (a, b) in enumerate(scene.edges)}

    def length(i: np.ndarray, j: np.ndarray) -> np.ndarray:
        return scene.rest_start[[key[(min(a, b), max(a, b))] for a, b in zip(i.tolist(), j.tolist())]]

    f = scene.faces
    a, b, c = length(f[:, 0], f[:, 1]), length(f[:, 0], f[:, 2]), length(f[:, 1], f[:, 2])
    x = (a * a + b * b - c * c) / (2.0 * a)
    y = np.sqrt(np.maximum(b * b - x * x, 1e-12 * b * b))
    rest = np.zeros((len(f), 2, 2))
    rest[:, 0, 0], rest[:, 0, 1], rest[:, 1, 1] = a, x, y
    return rest, 0.5 * a * y


def _arc(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Rotation vectors (C, 3) of the shortest arcs turning unit vectors a (C, 3) onto b (C, 3)."""
    cross = np.cross(a, b)
    n = np.linalg.norm(cross, axis=1, keepdims=True)
    angle = np.arctan2(n, (a * b).sum(axis=1, keepdims=True))
    out = np.where(n > 1e-12, cross / np.maximum(n, 1e-300) * angle, 0.0)
    flip = (n[:, 0] <= 1e-12) & ((a * b).sum(axis=1) < 0)  # opposite: half a turn about any perpendicular
    perp = np.cross(a[flip], np.eye(3)[np.argmin(np.abs(a[flip]), axis=1)])
    out[flip] = np.pi * perp / np.linalg.norm(perp, axis=1, keepdims=True)
    return out


def capsule_frames(scene: Scene, ends: np.ndarray):  # noqa: ANN201 - (positions (C, 3), scipy Rotation)
    """Each capsule's body frame for capsule ends (C, 2, 3): origin at the middle, local +Z (newton's capsule axis)
    along the capsule, turned from its rest frame by the shortest arc from the rest axis to the current one (so
    that it does not spin about its axis)."""
    from scipy.spatial.transform import Rotation

    def unit(e: np.ndarray) -> np.ndarray:
        d = e[:, 1] - e[:, 0]
        return d / np.linalg.norm(d, axis=1, keepdims=True)

    rest = unit(scene.ends_rest)
    z = np.tile([0.0, 0.0, 1.0], (len(rest), 1))
    rot = Rotation.from_rotvec(_arc(rest, unit(ends))) * Rotation.from_rotvec(_arc(z, rest))
    return ends.mean(axis=1), rot


@dataclass
class NewtonScene:
    """newton's model of the scene and what moves it: the solver, the collision pipeline and its contacts, two
    states, and the skin's collision mesh (a `newton.Mesh`, moved by us) with its shape index, or None."""

    model: object
    solver: object
    pipeline: object
    contacts: object
    states: list
    control: object
    skin: object | None
    skin_shape: int


def build_newton(scene: Scene, args: argparse.Namespace) -> NewtonScene:
    """newton's model of the scene: the cloth (same triangles, rest shapes and masses), the obi's vertices massless
    (moved by us), the capsules as kinematic bodies and the skin as a mesh whose vertices we move, the floor."""
    import newton

    builder = newton.ModelBuilder(up_axis=newton.Axis.Y)  # gravity -9.81 m/s² along Y
    _add_cloth(builder, scene, args)
    cfg = newton.ModelBuilder.ShapeConfig(has_shape_collision=False, mu=args.friction)  # touches the cloth only
    if args.colliders in ("capsules", "both"):
        _add_capsule_bodies(builder, scene, args.capsule_pieces, cfg)
    skin, skin_shape = None, -1
    if args.colliders in ("skin", "both"):
        skin = newton.Mesh(scene.skin[0], scene.body_faces.reshape(-1), compute_inertia=False)
        skin_shape = builder.add_shape_mesh(body=-1, mesh=skin, cfg=cfg)
    builder.add_ground_plane(height=scene.floor_y, cfg=cfg)
    if args.solver == "vbd":
        builder.color(include_bending=True)
    model = builder.finalize(device="cpu")
    model.soft_contact_ke = args.contact_ke
    model.soft_contact_kd = args.contact_kd
    model.soft_contact_mu = args.friction
    if args.solver == "vbd":
        solver = newton.solvers.SolverVBD(model, iterations=args.iterations, integrate_with_external_rigid_solver=True)
    else:
        solver = newton.solvers.SolverXPBD(model, iterations=args.iterations)
    pipeline = newton.CollisionPipeline(model, soft_contact_gap=args.margin)
    states = [model.state(), model.state()]
    return NewtonScene(model, solver, pipeline, pipeline.contacts(), states, model.control(), skin, skin_shape)


def _add_cloth(builder, scene: Scene, args: argparse.Namespace) -> None:  # noqa: ANN001
    """The kimono: newton's cloth mesh, then kitsuke's rest shapes and masses put in (the obi's vertices 0 kg)."""
    import warp as wp

    builder.add_cloth_mesh(
        pos=wp.vec3(0.0, 0.0, 0.0),
        rot=wp.quat_identity(),
        scale=1.0,
        vel=wp.vec3(0.0, 0.0, 0.0),
        vertices=scene.positions.tolist(),
        indices=scene.faces.reshape(-1).tolist(),
        density=0.1,
        tri_ke=args.tri_ke,
        tri_ka=args.tri_ke,
        tri_kd=args.tri_kd,
        edge_ke=args.edge_ke,
        edge_kd=args.edge_kd,
        add_springs=args.solver == "xpbd",
        spring_ke=args.spring_ke,
        spring_kd=args.spring_kd,
        particle_radius=args.radius,
    )
    if len(builder.tri_indices) != len(scene.faces):
        raise RuntimeError("newton dropped degenerate triangles of the kimono")
    rest, areas = _rest_triangles(scene)
    builder.tri_poses = np.linalg.inv(rest).tolist()
    builder.tri_areas = areas.tolist()
    mass = scene.mass.copy()
    mass[scene.held] = 0.0  # the obi holds them: moved by us, as kitsuke's SkinHold
    builder.particle_mass = mass.tolist()


def _add_capsule_bodies(builder, scene: Scene, pieces: int, cfg) -> None:  # noqa: ANN001
    """One kinematic body per tapered capsule, carrying `pieces` capsules along its axis (local +Z) with the
    taper's radius at each piece's middle."""
    import warp as wp

    centre, rot = capsule_frames(scene, scene.ends_rest)
    lengths = np.linalg.norm(scene.ends_rest[:, 1] - scene.ends_rest[:, 0], axis=1)
    for c in range(len(lengths)):
        xform = wp.transform(wp.vec3(*centre[c]), wp.quat(*rot[c].as_quat()))
        body = builder.add_body(xform=xform, is_kinematic=True)
        piece = lengths[c] / pieces
        for k in range(pieces):
            t = (k + 0.5) / pieces
            radius = (1.0 - t) * scene.radii[c, 0] + t * scene.radii[c, 1]
            builder.add_shape_capsule(
                body,
                xform=wp.transform(wp.vec3(0.0, 0.0, (t - 0.5) * lengths[c]), wp.quat_identity()),
                radius=float(radius),
                half_height=float(0.5 * piece),
                cfg=cfg,
            )


def body_path(scene: Scene, ends0: np.ndarray, ends1: np.ndarray, n_sub: int, h: float):  # noqa: ANN201
    """The capsules' poses (n_sub + 1, C, 7) [p, q xyzw] at the substeps' bounds, the ends moving linearly from
    ends0 to ends1 (C, 2, 3), and their spatial velocities (n_sub, C, 6) [v, w] over each substep of h seconds."""
    t = np.linspace(0.0, 1.0, n_sub + 1)[:, None, None, None]
    frames = [capsule_frames(scene, e) for e in (1.0 - t) * ends0 + t * ends1]
    q = np.array([np.concatenate([p, r.as_quat()], axis=1) for p, r in frames])  # scipy and warp: (x, y, z, w)
    qd = np.array(
        [
            np.concatenate([(p1 - p0) / h, (r1 * r0.inv()).as_rotvec() / h], axis=1)
            for (p0, r0), (p1, r1) in zip(frames[:-1], frames[1:])
        ]
    )
    return q, qd


def _pose_capsules(ns: NewtonScene, solver: str, q0: np.ndarray, q1: np.ndarray, qd: np.ndarray) -> None:
    """Put the kinematic capsules where the substep needs them. VBD with external rigid integration reads the
    substep's start pose from the input state and its end pose and velocity from the output state; XPBD copies a
    kinematic body's pose and velocity from the input state, so it gets the end pose there."""
    s0, s1 = ns.states
    if s0.body_q is None:
        return
    if solver == "vbd":
        s0.body_q.numpy()[:] = q0
        s1.body_q.numpy()[:] = q1
        s0.body_qd.numpy()[:] = qd
        s1.body_qd.numpy()[:] = qd
    else:
        s0.body_q.numpy()[:] = q1
        s0.body_qd.numpy()[:] = qd


def _pose_skin(ns: NewtonScene, points: np.ndarray, velocity: np.ndarray) -> None:
    """Move the skin's collision mesh to `points` (Vb, 3) with per-vertex `velocity` (friction), refit its BVH and
    its bounds (the broad phase culls particles with them)."""
    if ns.skin is None:
        return
    mesh = ns.skin.mesh
    mesh.points.numpy()[:] = points
    mesh.velocities.numpy()[:] = velocity
    mesh.refit()
    ns.model.shape_collision_aabb_lower.numpy()[ns.skin_shape] = points.min(axis=0)
    ns.model.shape_collision_aabb_upper.numpy()[ns.skin_shape] = points.max(axis=0)


def newton_frame(ns: NewtonScene, scene: Scene, f: int, args: argparse.Namespace) -> np.ndarray:
    """Advance newton's cloth by frame f: substeps along which the capsules, the skin and the obi's vertices move
    linearly from the previous frame's pose to frame f's. Returns the cloth's positions (V, 3)."""
    n_sub = args.substeps
    h = scene.dt / n_sub
    ends0, hold0, skin0 = (
        (scene.ends[f - 1], scene.hold[f - 1], scene.skin[f - 1])
        if f
        else (scene.ends_rest, scene.hold_rest, scene.skin[0])
    )
    q, qd = body_path(scene, ends0, scene.ends[f], n_sub, h)
    skin_v = (scene.skin[f] - skin0) / scene.dt
    for s in range(n_sub):
        t = (s + 1) / n_sub
        _pose_capsules(ns, args.solver, q[s], q[s + 1], qd[s])
        _pose_skin(ns, (1.0 - t) * skin0 + t * scene.skin[f], skin_v)
        s0, s1 = ns.states
        s0.particle_q.numpy()[scene.held] = (1.0 - t) * hold0 + t * scene.hold[f]  # as kitsuke's SkinHold
        s0.particle_qd.numpy()[scene.held] = 0.0
        s0.clear_forces()
        ns.pipeline.collide(s0, ns.contacts)
        ns.solver.step(s0, s1, ns.control, ns.contacts, h)
        ns.states.reverse()
    return ns.states[0].particle_q.numpy().astype(np.float64)


def run_newton(scene: Scene, args: argparse.Namespace) -> dict:
    """Simulate the scene with newton on the CPU, compiling into --warp-cache or a fresh temporary cache."""
    import warp as wp

    wp.config.quiet = True
    if args.warp_cache is not None:
        wp.config.kernel_cache_dir = str(args.warp_cache)
        wp.init()
        return _run_newton(scene, args)
    with tempfile.TemporaryDirectory(prefix="kitsuke-warp-") as cache:
        wp.config.kernel_cache_dir = cache
        wp.init()
        return _run_newton(scene, args)


def _run_newton(scene: Scene, args: argparse.Namespace) -> dict:
    """newton's run; timed per frame: posing the capsules, the skin mesh and the obi's vertices, and the substeps
    (collision detection and solver step each)."""
    import newton

    t0 = time.perf_counter()
    ns = build_newton(scene, args)
    built = time.perf_counter() - t0
    per_frame = []
    for f in range(scene.n_frames):
        t0 = time.perf_counter()
        x = newton_frame(ns, scene, f, args)
        per_frame.append(measure(scene, f, x, time.perf_counter() - t0))
        if not np.isfinite(x).all():
            break
    stiffness = f"tri_ke = tri_ka {args.tri_ke:g}" if args.solver == "vbd" else f"spring_ke {args.spring_ke:g}"
    settings = (
        f"{args.solver.upper()}, {args.substeps} substeps x {args.iterations} iterations, {stiffness}, "
        f"edge_ke {args.edge_ke:g}, colliders {args.colliders} ({args.capsule_pieces} capsules per taper), "
        f"contact ke {args.contact_ke:g} mu {args.friction:g}, radius {1e3 * args.radius:g} mm, "
        f"gap {1e3 * args.margin:g} mm, no self-contact"
    )
    extra = {
        "tool": f"newton {newton.__version__} {args.solver.upper()}",
        "solver": settings,
        "build_s": round(built, 2),
        "warp_cache": "empty (compiled in this run)" if args.warp_cache is None else str(args.warp_cache),
    }
    return summarise(scene, per_frame, extra)


# --------------------------------------------------------------------------------------------------------------
# Report
# --------------------------------------------------------------------------------------------------------------


def machine() -> dict:
    """This machine: CPU, cores, load averages (other jobs share it)."""
    cpu = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    uptime = subprocess.run(["uptime"], capture_output=True, text=True, check=False).stdout.strip()
    return {
        "cpu": cpu,
        "cores": os.cpu_count(),
        "load_average": list(os.getloadavg()),
        "uptime": uptime,
        "kitsuke_commit": kitsuke_commit(),
    }


def kitsuke_commit() -> str:
    """The checkout's commit, "+edits" when tracked files differ from it (read-only: no git lock taken)."""

    def git(*a: str) -> str:
        env = {**os.environ, "GIT_OPTIONAL_LOCKS": "0"}
        run = subprocess.run(["git", "-C", str(ROOT), *a], capture_output=True, text=True, check=False, env=env)
        return run.stdout.strip()

    commit = git("rev-parse", "--short", "HEAD") or "unknown"
    return commit + ("+edits" if git("status", "--porcelain", "--untracked-files=no") else "")


def _pct(x: float | None) -> str:
    return "-" if x is None else f"{100 * x:.1f}"


def table(results: list[dict]) -> str:
    """The markdown table of the summaries."""
    rows = [
        "| tool | first frame s (compile) | s / frame median (mean) | frames within targets | max strain % median / "
        "worst | p99 strain % median / worst | > 5 mm inside: worst count / deepest mm (frames with any) | the same, "
        "obi's held vertices apart |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in results:
        within = f"{r['frames_within_targets']} / {r['clip_frames']}"
        if r["diverged_at_frame"] is not None:
            within += f" (diverged at frame {r['diverged_at_frame']})"
        pen = free = "-"
        if "penetration_count_worst" in r:
            pen = f"{r['penetration_count_worst']} / {r['penetration_deepest_mm']:.1f} ({r['frames_with_penetration']})"
            free = f"{r['penetration_free_count_worst']} / {r['penetration_free_deepest_mm']:.1f}"
        rows.append(
            f"| {r['tool']} | {r['first_frame_s']:.1f} | {r['frame_s_median']:.3f} ({r['frame_s_mean']:.3f}) "
            f"| {within} | {_pct(r.get('strain_max_median'))} / {_pct(r.get('strain_max_worst'))} "
            f"| {_pct(r.get('strain_p99_median'))} / {_pct(r.get('strain_p99_worst'))} | {pen} | {free} |"
        )
    return "\n".join(rows)


def parse_args() -> argparse.Namespace:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--frames", type=int, default=60, help="clip frames after the lead-in (default 60)")
    ap.add_argument("--json", type=Path, help="write the summaries and per-frame measures here")
    ap.add_argument("--no-newton", action="store_true", help="run the kitsuke half only")
    ap.add_argument("--no-kitsuke", action="store_true", help="run the newton half only")
    g = ap.add_argument_group("newton")
    g.add_argument("--solver", choices=("vbd", "xpbd"), default="vbd", help="newton's cloth solver (default vbd)")
    g.add_argument("--substeps", type=int, default=20, help="substeps per 1/30 s frame (default 20, as kitsuke)")
    g.add_argument("--iterations", type=int, default=2, help="solver iterations per substep (default 2)")
    g.add_argument("--tri-ke", type=float, default=1e5, help="VBD membrane stiffness tri_ke = tri_ka (default 1e5)")
    g.add_argument("--tri-kd", type=float, default=1e-5, help="VBD membrane damping (default 1e-5)")
    g.add_argument(
        "--spring-ke",
        type=float,
        default=1.0,
        help="XPBD spring stiffness, N/m (default 1: newton's XPBD sums its "
        "Jacobi corrections, and on this light cloth 30 N/m already diverges in the first frame)",
    )
    g.add_argument("--spring-kd", type=float, default=0.0, help="XPBD edge spring damping (default 0)")
    g.add_argument("--edge-ke", type=float, default=1e-3, help="bending stiffness (default 1e-3)")
    g.add_argument("--edge-kd", type=float, default=1e-5, help="bending damping (default 1e-5)")
    g.add_argument("--radius", type=float, default=4e-3, help="particle radius = distance kept off the body, m")
    g.add_argument("--margin", type=float, default=1e-2, help="soft contact detection gap, m (default 0.01)")
    g.add_argument("--contact-ke", type=float, default=1e5, help="body contact stiffness (default 1e5)")
    g.add_argument("--contact-kd", type=float, default=1e-3, help="body contact damping (default 1e-3)")
    g.add_argument("--friction", type=float, default=0.4, help="body contact friction (default 0.4, as kitsuke)")
    g.add_argument(
        "--colliders",
        choices=("both", "capsules", "skin"),
        default="both",
        help="the body as newton sees it: "
        "kitsuke's capsules (kinematic bodies) and/or the skin (a mesh moved every substep; default both)",
    )
    g.add_argument("--capsule-pieces", type=int, default=3, help="plain capsules per tapered capsule (default 3)")
    g.add_argument("--warp-cache", type=Path, help="warp kernel cache to use (default: an empty one, compiled anew)")
    args = ap.parse_args()
    for name in ("frames", "substeps", "iterations", "capsule_pieces"):
        if getattr(args, name) < 1:
            ap.error(f"--{name.replace('_', '-')} must be at least 1")
    return args


def newton_available() -> bool:
    try:
        import newton  # noqa: F401
        import warp  # noqa: F401
    except ImportError:
        print(f"newton is not installed ({INSTALL_HINT}); running the kitsuke half only.", flush=True)
        return False
    return True


def report(scene: Scene, start: dict, results: list[dict], before: dict, after: dict) -> None:
    """Print what was run, on what, and the table."""
    print()
    print(
        f"Machine: {after['cpu']}, {after['cores']} cores, CPU only (this machine). uptime before: {before['uptime']}; "
        f"after: {after['uptime']}. A load average above ~0.5 before the run means other jobs shared the cores. "
        f"kitsuke at {after['kitsuke_commit']}."
    )
    print(
        f"Kimono {len(scene.positions)} vertices, {len(scene.faces)} faces, {len(scene.held)} held by the obi; "
        f"{scene.n_lead} lead-in + {scene.n_frames - scene.n_lead} clip frames at {1 / scene.dt:g} fps. Dressed "
        f"start on the rest body: max strain {100 * start['strain_max']:.1f} %, p99 {100 * start['strain_p99']:.1f} %, "
        f"{start['edges_over_10_percent']} of {start['edges']} edges over 10 %, {start['penetration_count']} vertices "
        "> 5 mm inside."
    )
    for r in results:
        built = f"; model built in {r['build_s']} s, warp kernel cache {r['warp_cache']}" if "build_s" in r else ""
        print(f"- {r['tool']}: {r['solver']}{built}")
    print(
        "Time per frame: frames 2..n (the first pays the one-time kernel compilation, shown apart); quality over "
        "the clip frames (targets: no vertex > 5 mm inside the posed skin, max strain <= 10 %)."
    )
    print()
    print(table(results))


def main() -> int:
    args = parse_args()
    use_newton = not args.no_newton and newton_available()
    before = machine()
    t = time.perf_counter()
    scene = build_scene(args.frames)
    print(f"scene dressed and posed in {time.perf_counter() - t:.0f} s", flush=True)
    start = start_quality(scene)
    results = []
    if not args.no_kitsuke:
        results.append(run_kitsuke(scene))
        print(f"kitsuke done: {results[-1]['frame_s_median']:.3f} s / frame", flush=True)
    if use_newton:
        results.append(run_newton(scene, args))
        print(f"newton done: {results[-1]['frame_s_median']:.3f} s / frame", flush=True)
    after = machine()
    report(scene, start, results, before, after)
    if args.json:
        out = {"machine_before": before, "machine_after": after, "dressed_start": start, "results": results}
        args.json.write_text(json.dumps(out, indent=1))
        print(f"\nwrote {args.json}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
