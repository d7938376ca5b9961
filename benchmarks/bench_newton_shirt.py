"""Benchmark: kitsuke's wrap vs NVIDIA newton (VBD cloth, CPU) on GarmentCode's shirt and mean_all, same run.

    python benchmarks/bench_newton_shirt.py [--sew-frames 40] [--frames 60] [--substeps 5]
    python benchmarks/bench_newton_shirt.py --pattern DESIGN_specification.json [--perturb] [--seam-ke-start 1e2]

With --pattern, any GarmentCode design instead of the shirt: kitsuke dresses it with the strokes `kitsuke strokes
suggest` makes (--perturb: changed as `bench_corpus` changes them), newton drapes it from its placement. Both
results are then compared edge for edge (the same pattern mesh): where each tool's worst edges lie, and what the
other tool's cloth carries there. A design whose cloth both tools strain past 10 % at the same place is cut too
small for the body there (measured: a fitted bodice's armhole corner, 20-27 % in both).

Takes about 4 minutes on 2 CPU cores (newton: ~50 s of kernel compilation, then ~70 s per drape).

newton is not a kitsuke dependency (`pip install newton==1.8.0 warp-lang==1.19.0` into the same environment);
without it this script says so and exits 0.

newton's side: the shirt's pattern mesh (1.5 cm edges) starts at GarmentCode's own panel placement
(`PatternMesh.positions_m`); every piece is a flat panel moved rigidly, so its placed triangles are its rest shape.
The seams are zero-rest-length springs between the stitched vertex pairs (`PatternMesh.seam_vertices`; VBD supports
springs, so nothing is welded); mean_all is a static collision mesh. The panels are sewn weightless first
(--sew-frames), then gravity (-9.81 m/s² along Y) settles the shirt (--frames). The whole run is timed
twice: the first with an empty warp kernel cache (so it includes the kernel compilation), the second warm.
Both results are measured with `kitsuke.metrics.quality_report` (SPEC §6) against the same body, with rest lengths
from the pattern; newton's seam gap is taken over the stitched pairs (kitsuke's garment shares its seam vertices).
A front render of both results goes to --png.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
BODY = ROOT / "tests/data/bodies/mean_all.obj"
SHIRT = ROOT / "tests/data/pattern/shirt_mean_specification.json"
STROKES = ROOT / "src/kitsuke/assets/strokes/shirt_mean_all.json"


def _rest(pm) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Edges (E, 2) int64, rest lengths (E,) metres and rest areas (F,) m² of the pattern mesh's flat pieces."""
    from kitsuke.metrics import mesh_edges

    edges = mesh_edges(pm.faces)
    flat = np.zeros((pm.n_vertices, 3))
    flat[:, :2] = pm.vertices_cm / 100.0
    lengths = np.linalg.norm(flat[edges[:, 0]] - flat[edges[:, 1]], axis=1)
    tri = flat[pm.faces]
    areas = 0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    return edges, lengths, areas


def run_newton(pm, body_mesh, args) -> tuple[np.ndarray, float, float, np.ndarray]:
    """Drape the pattern mesh on the body with newton's VBD solver on the CPU.

    Returns the positions (V, 3) float64 metres, the wall seconds (model building included), the seconds spent
    building the model (colouring and finalize included), and the particle speeds at the end ((V,) m/s, how settled
    the cloth is).
    """
    import newton
    import warp as wp

    t0 = time.perf_counter()
    builder = newton.ModelBuilder(up_axis=newton.Axis.Y)  # gravity: -9.81 m/s² along Y
    builder.add_cloth_mesh(
        pos=wp.vec3(0.0, 0.0, 0.0),
        rot=wp.quat_identity(),
        scale=1.0,
        vel=wp.vec3(0.0, 0.0, 0.0),
        vertices=[wp.vec3(*p) for p in pm.positions_m],
        indices=pm.faces.reshape(-1).tolist(),
        density=args.density,
        tri_ke=args.tri_ke,
        tri_ka=args.tri_ke,
        tri_kd=args.tri_kd,
        edge_ke=args.edge_ke,
        edge_kd=args.edge_kd,
        particle_radius=args.radius,
    )
    first = len(builder.spring_rest_length)
    for pairs in pm.seam_vertices:
        for a, b in np.asarray(pairs, dtype=np.int64):
            builder.add_spring(int(a), int(b), args.seam_ke, args.seam_kd, 0.0)
    # add_spring takes the rest length from the current distance; a stitch pulls the two sides together.
    for k in range(first, len(builder.spring_rest_length)):
        builder.spring_rest_length[k] = 0.0
    builder.add_shape_mesh(
        body=-1,
        mesh=newton.Mesh(body_mesh.vertices.astype(np.float32), body_mesh.faces.reshape(-1).astype(np.int32)),
    )
    builder.color(include_bending=True)
    model = builder.finalize(device="cpu")
    model.soft_contact_ke = args.contact_ke
    model.soft_contact_kd = args.contact_kd
    model.soft_contact_mu = args.friction
    solver = newton.solvers.SolverVBD(model, iterations=args.iterations)
    pipeline = newton.CollisionPipeline(model, soft_contact_gap=args.margin)
    contacts = pipeline.contacts()
    s0, s1, control = model.state(), model.state(), model.control()
    built = time.perf_counter() - t0
    dt = 1.0 / 60.0 / args.substeps
    # Sew first, weightless (as GarmentCode's own simulation does): under gravity from the first step the panels
    # fall past the shoulders before the stitches close, and the shirt ends at the feet.
    model.set_gravity((0.0, 0.0, 0.0))
    n_springs = len(builder.spring_rest_length)
    for frame in range(args.sew_frames + args.frames):
        if args.seam_ke_start is not None and frame <= args.sew_frames and n_springs > first:
            # Stitches tightened geometrically over the sewing frames: stiff from the first frame, a tight skirt's
            # first step tore it (228 % strain); soft throughout, its seams stayed open and it fell.
            f = min(frame / max(args.sew_frames, 1), 1.0)
            ke = np.array(model.spring_stiffness.numpy())
            ke[first:] = args.seam_ke_start * (args.seam_ke / args.seam_ke_start) ** f
            model.spring_stiffness.assign(ke)
        if frame == args.sew_frames:
            model.set_gravity((0.0, -9.81, 0.0))
        for _ in range(args.substeps):
            s0.clear_forces()
            # Body contacts found once per frame let the falling cloth pass the body by up to 10 cm: every step.
            pipeline.collide(s0, contacts)
            solver.step(s0, s1, control, contacts, dt)
            s0, s1 = s1, s0
    positions = s0.particle_q.numpy().astype(np.float64)
    wall = time.perf_counter() - t0
    return positions, wall, built, np.linalg.norm(s0.particle_qd.numpy(), axis=1)


def _edge_for_edge(g, positions: np.ndarray, pm, edges: np.ndarray, rest: np.ndarray) -> None:
    """Print each tool's 99th-percentile strain and its five worst edges (piece, place), with the strain the other
    tool's cloth has on the same edge. kitsuke's garment shares seam vertices; its pattern mesh's vertex k is garment
    vertex g.pattern_vertex[k] (both tools start from the same mesh_pattern at 1.5 cm)."""
    if g.pattern_mesh.n_vertices != pm.n_vertices:
        print("(kitsuke's pattern mesh had corners repaired: no edge-for-edge comparison)")
        return
    kit = g.positions[g.pattern_vertex]
    both = {}
    for tool, x in (("kitsuke", kit), ("newton", positions)):
        both[tool] = np.linalg.norm(x[edges[:, 1]] - x[edges[:, 0]], axis=1) / rest - 1.0
    piece = np.searchsorted(pm.piece_vertices[:, 1], edges[:, 0], side="right")
    for tool, other in (("kitsuke", "newton"), ("newton", "kitsuke")):
        e = both[tool]
        p99 = 100 * np.percentile(np.abs(e), 99)
        print(f"{tool}: p99 strain {p99:.1f} %, {(np.abs(e) > 0.1).sum()} edges over 10 %")
        x = kit if tool == "kitsuke" else positions
        for k in np.argsort(-np.abs(e))[:5]:
            at = 0.5 * (x[edges[k, 0]] + x[edges[k, 1]])
            print(
                f"  {100 * e[k]:+6.1f} % on {pm.piece_names[piece[k]]} at ({at[0]:+.3f}, {at[1]:.3f}, {at[2]:+.3f}) m;"
                f" {other} there {100 * both[other][k]:+.1f} %"
            )


def _row(tool: str, first: float, warm: float, r) -> str:
    return (
        f"| {tool} | {first:.2f} | {warm:.2f} | {r.n_vertices} "
        f"| {r.penetration_count} / {r.penetration_deepest_mm:.1f} "
        f"| {100 * r.strain_mean:.1f} / {100 * r.strain_max:.1f} | {r.seam_gap_mm:.1f} | {r.inverted_count} |"
    )


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--frames", type=int, default=60, help="frames of 1/60 s under gravity after sewing (default 60)")
    ap.add_argument("--sew-frames", type=int, default=40, help="weightless sewing frames first (default 40)")
    ap.add_argument("--substeps", type=int, default=5, help="VBD steps per frame (default 5)")
    ap.add_argument("--iterations", type=int, default=10, help="VBD iterations per step (default 10)")
    ap.add_argument("--density", type=float, default=0.15, help="cloth mass, kg/m² (default 0.15)")
    ap.add_argument("--tri-ke", type=float, default=1e4, help="membrane stiffness tri_ke = tri_ka (default 1e4)")
    ap.add_argument("--tri-kd", type=float, default=1e-4, help="membrane damping (default 1e-4)")
    ap.add_argument("--edge-ke", type=float, default=1e-3, help="bending stiffness (default 1e-3)")
    ap.add_argument("--edge-kd", type=float, default=1e-5, help="bending damping (default 1e-5)")
    ap.add_argument("--seam-ke", type=float, default=1e5, help="stitch spring stiffness, N/m (default 1e5)")
    ap.add_argument("--seam-kd", type=float, default=1e-2, help="stitch spring damping (default 1e-2)")
    ap.add_argument("--radius", type=float, default=3e-3, help="particle radius, m (default 3e-3)")
    ap.add_argument("--margin", type=float, default=1e-2, help="soft contact margin, m (default 1e-2)")
    ap.add_argument("--contact-ke", type=float, default=1e5, help="body contact stiffness (default 1e5)")
    ap.add_argument("--contact-kd", type=float, default=1e-2, help="body contact damping (default 1e-2)")
    ap.add_argument("--friction", type=float, default=0.2, help="body contact friction (default 0.2)")
    ap.add_argument("--png", type=Path, default=Path("/work/scratch/newton/kitsuke_vs_newton.png"))
    ap.add_argument("--pattern", type=Path, default=None, help="a GarmentCode design instead of the shirt (see above)")
    ap.add_argument("--perturb", action="store_true", help="--pattern: its suggested strokes changed as by a hand")
    ap.add_argument(
        "--seam-ke-start", type=float, default=None, help="ramp the stitches' stiffness to --seam-ke while sewing"
    )
    args = ap.parse_args()
    try:
        import newton
        import warp as wp
    except ImportError:
        print("newton is not installed (pip install newton); skipping the newton comparison.")
        return 0
    from kitsuke.body import load_body
    from kitsuke.dressing import read_strokes
    from kitsuke.dressing.wrap import wrap
    from kitsuke.errors import ComputationError
    from kitsuke.metrics import quality_report
    from kitsuke.pattern import load_pattern, mesh_pattern

    body = load_body(BODY)
    pattern = load_pattern(args.pattern or SHIRT)
    if args.pattern is None:
        strokes = read_strokes(STROKES)
    else:
        sys.path.insert(0, str(Path(__file__).parent))
        from bench_corpus import rng_of

        from kitsuke.cloth import BodyCollider
        from kitsuke.dressing import perturb_strokes, suggest_strokes

        surface = BodyCollider.from_body(body).surface_for(body.mesh)
        strokes = suggest_strokes(body, pattern, surface=surface)
        if args.perturb:
            strokes = perturb_strokes(strokes, surface, rng_of(args.pattern))

    walls = []
    for _ in range(3):  # the first run in the process, then the faster of two warm ones
        t = time.perf_counter()
        try:
            g = wrap(body, pattern, strokes)
        except ComputationError as e:  # a failed wrap is still compared (and said so)
            print(f"kitsuke: {e}")
            g = e.result
        walls.append(time.perf_counter() - t)
    rows = [_row("kitsuke wrap", walls[0], min(walls[1:]), g.report)]

    pm = mesh_pattern(pattern, edge_length=1.5)
    edges, rest_lengths, rest_areas = _rest(pm)
    seams = [(s[:, 0], s[:, 1]) for s in pm.seam_vertices]
    placed = quality_report(
        pm.positions_m, pm.faces, body.mesh, rest_lengths=rest_lengths, edges=edges, seams=seams, rest_areas=rest_areas
    )
    with tempfile.TemporaryDirectory() as cache:
        wp.config.kernel_cache_dir = cache  # an empty cache: the first run pays the whole compilation
        wp.config.quiet = True
        wp.init()
        newton_walls, builds = [], []
        for _ in range(2):
            positions, wall, built, speed = run_newton(pm, body.mesh, args)
            newton_walls.append(wall)
            builds.append(built)
    nr = quality_report(
        positions, pm.faces, body.mesh, rest_lengths=rest_lengths, edges=edges, seams=seams, rest_areas=rest_areas
    )
    rows.append(_row(f"newton {newton.__version__} VBD (CPU)", newton_walls[0], newton_walls[1], nr))

    print(
        f"{pattern.name}, 1.5 cm edges: {pm.n_vertices} pattern vertices, {pm.n_faces} faces, "
        f"{sum(len(s) for s in pm.seam_vertices)} stitched pairs; body mean_all"
    )
    print(
        f"GarmentCode placement before simulation: penetration {placed.penetration_count}, strain max "
        f"{100 * placed.strain_max:.2f} %, seam gap {placed.seam_gap_mm:.0f} mm"
    )
    print(
        f"newton: {args.sew_frames} weightless sewing frames + {args.frames} frames under gravity, "
        f"{args.substeps} substeps x {args.iterations} iterations (dt {1e3 / 60 / args.substeps:.2f} ms), "
        f"tri_ke {args.tri_ke:g}, edge_ke {args.edge_ke:g}, seam springs ke {args.seam_ke:g} rest 0, "
        f"contact ke {args.contact_ke:g} gap {args.margin:g} m, radius {args.radius:g} m"
    )
    print(
        f"newton model building (incl. colouring, finalize, solver set-up): first {builds[0]:.1f} s, warm "
        f"{builds[1]:.1f} s; particle speed at the end: mean {1e3 * speed.mean():.1f} mm/s, max "
        f"{1e3 * speed.max():.0f} mm/s"
    )
    print()
    print(
        "| tool | wall s (first, incl. compile) | wall s (warm) | vertices | penetration count / deepest mm "
        "| strain mean % / max % | seam gap mm | inverted |"
    )
    print("|---|---|---|---|---|---|---|---|")
    for r in rows:
        print(r)
    print()
    _edge_for_edge(g, positions, pm, edges, rest_lengths)

    from kitsuke.geometry import TriMesh
    from kitsuke.render import Renderer, write_png

    renderer = Renderer()
    left = renderer.render([body.mesh, TriMesh(g.positions, g.faces)], view="front")
    right = renderer.render([body.mesh, TriMesh(positions, pm.faces)], view="front")
    args.png.parent.mkdir(parents=True, exist_ok=True)
    write_png(args.png, np.concatenate([left, right], axis=1))
    print(f"render (left kitsuke, right newton): {args.png}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
