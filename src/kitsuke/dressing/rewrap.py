"""Re-wrap (SPEC §4.1 item 5): the stroke operation on a garment already on the body; pins limit what moves.

    from kitsuke.dressing.rewrap import rewrap
    result = rewrap(body, dressed, strokes, pins=[[0.0, 1.2, -0.15]])    # strokes with "target": "garment"
    result.garment (a GarmentFile: write it with write_garment_obj), result.report, result.stroke_residual_m

The strokes file is the wrap's (SPEC §3.2) with `"target": "garment"`: each pattern stroke names a piece of the
dressed garment (cm, piece coordinates, as in its OBJ's `vt` x 100); its 3D stroke is drawn on what the user sees,
the dressed garment's surface. Steps:

1. The triangles each pattern stroke crosses are laid on the body along the 3D stroke (the wrap's transfer:
   arc length along, offset across laid out on the surface).
2. The rest of the garment follows: each vertex takes the displacement of its nearest stroke vertex (shortest
   path over the cloth), scaled by a weight that is 1 on the stroke and falls smoothly to 0 at the pins
   (smoothstep of d_pin / (d_stroke + d_pin)); without pins the whole garment moves with its strokes.
3. The global closing relaxation (`_solve.GlobalRelax`, body contacts inside the solve) with the stroke
   triangles and the pins held, then a short gravity settle (the strokes still held unless `release_strokes`),
   with edge-length restoration (`kitsuke.cloth.restore_lengths`) before and after it, and `kitsuke.cloth.untangle`
   opens the triangles left folded (the pins and strokes still held); the wrap's polish ends it (kept where it
   is better, `_polish_step`).
"""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass, field

import numpy as np

from ..cloth import BodyCollider, ClothModel, ClothParams, ClothState, collide, folded_faces
from ..errors import InputError
from ..geometry import TriMesh
from ..geometry.surface import Surface
from ..metrics import QualityReport, quality_report
from ._crossing import segments_cross_triangles
from ._drag_field import follow_weights
from ._place import RESIDUAL_SAMPLES, body_path, lay_along, locate_in_triangles, polyline_distance
from ._polish_step import PolishSettings, polish_step
from ._polyline import resample_polyline
from ._solve import CG_ITERATIONS
from ._stages import (
    Closing,
    Finishing,
    Settling,
    StageLog,
    Untangling,
    close_stage,
    finish_stage,
    run_stage,
    settle_stage,
    untangle_stage,
)
from .export import GarmentFile, as_garment_file
from .strokes import Strokes, strokes_on_surface
from .wrap import offset_as_dressed
from .wrap_settings import CloseSettings, LengthSettings, SettleSettings

#: Largest distance, metres, from a pin point to the garment vertex it snaps to (as in the drags file).
PIN_SNAP_M = 0.05


@dataclass(frozen=True)
class RewrapParams:
    """Options of `rewrap`.

    lift_m : the stroke triangles are laid this far off the body, metres (as in the wrap).
    close_iterations : iterations of the global relaxation with the strokes and pins held.
    settle_iterations : relaxation iterations with gravity afterwards (0: none).
    release_strokes : let the stroke triangles go for the settle. False (default) keeps them where the strokes
        put them: a part moved against gravity (a hem turned up, a sleeve lifted) would otherwise fall back.
    contact_weight : body contacts inside the global solve (see WrapParams).
    length_sweeps : sweeps of `kitsuke.cloth.restore_lengths` before and after the settle, pins and held strokes
        kept (see WrapParams).
    untangle_rounds : most rounds of `kitsuke.cloth.untangle` at the end (see WrapParams).
    untangle_iterations : relaxation iterations of each untangle round: 60, as a drag's release, since the re-wrap
        relaxes the whole garment, whose finest triangles (the wrap refined a kimono's sleeves at the elbows down to
        2 mm) fold more easily than its 1.5 cm ones (the demo's kimono, hem turned up, on the default body moved by
        1 nm: 2 folded at an elbow after 30, none after 60).
    polish_rounds : rounds of the wrap's polish after that (`_polish_step`, without refinement), kept only where
        it lowers the max strain with nothing folded (0: none).
    cloth : ClothParams of the relaxation.
    """

    lift_m: float = 0.004
    close_iterations: int = 40
    settle_iterations: int = 30
    release_strokes: bool = False
    contact_weight: float = 20.0
    length_sweeps: int = 300
    untangle_rounds: int = 10
    untangle_iterations: int = 60
    polish_rounds: int = 8
    cloth: ClothParams = field(default_factory=lambda: ClothParams(max_stretch=None))

    def __post_init__(self) -> None:
        if not (
            self.lift_m >= 0
            and self.close_iterations >= 1
            and self.settle_iterations >= 0
            and self.untangle_rounds >= 0
            and self.untangle_iterations >= 1
            and self.length_sweeps >= 0
            and self.polish_rounds >= 0
        ):
            raise InputError(
                "rewrap parameters lift_m >= 0, close_iterations >= 1, settle_iterations >= 0, "
                "untangle_rounds >= 0, untangle_iterations >= 1, length_sweeps >= 0, polish_rounds >= 0 required"
            )
        if not self.contact_weight >= 0:
            raise InputError("rewrap parameter contact_weight must be >= 0")


@dataclass
class Rewrapped:
    """The result of `rewrap`.

    garment : the garment after the re-wrap (positions changed; topology and rest shape as before).
    pinned : (V,) bool, the pinned vertices (they have not moved). strokes : (V,) bool, the vertices laid along
    the strokes. moved_m : (V,) float64 metres, how far each vertex moved.
    stroke_ids, stroke_residual_m : per stroke, the largest distance of the pattern stroke (on the garment) to its
    3D stroke (traced on the body) after the settle, metres.
    report : SPEC §6 quality. timings : seconds per step.
    """

    garment: GarmentFile
    pinned: np.ndarray
    strokes: np.ndarray
    moved_m: np.ndarray
    stroke_ids: list[int]
    stroke_residual_m: np.ndarray
    report: QualityReport | None
    timings: dict[str, float]

    def summary(self) -> dict:
        """JSON-ready counts, stroke residuals, what moved and the quality report."""
        return {
            "name": self.garment.name,
            "operation": "rewrap",
            "vertices": len(self.garment.positions),
            "pinned": int(self.pinned.sum()),
            "moved_mm": {
                "max": round(float(self.moved_m.max(initial=0.0)) * 1e3, 2),
                "pinned_max": round(float(self.moved_m[self.pinned].max(initial=0.0)) * 1e3, 3),
            },
            "timings_s": {k: round(v, 4) for k, v in self.timings.items()},
            "strokes": [
                {"id": i, "residual_mm": round(float(r) * 1e3, 2)}
                for i, r in zip(self.stroke_ids, self.stroke_residual_m, strict=True)
            ],
            "quality": None if self.report is None else self.report.to_dict(),
        }


def snap_pins(garment: GarmentFile, points, *, source: str | None = None) -> np.ndarray:
    """(V,) bool: the garment vertex nearest each pin point (n, 3) metres; InputError for a point farther than
    PIN_SNAP_M from the garment or not finite."""
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 3) if len(points) else np.zeros((0, 3))
    if not np.isfinite(pts).all():
        raise InputError("a pin point is NaN or infinite", source)
    mask = np.zeros(len(garment.positions), dtype=bool)
    if len(pts):
        from scipy.spatial import cKDTree

        d, i = cKDTree(garment.positions).query(pts)
        far = d > PIN_SNAP_M
        if far.any():
            k = int(np.argmax(far))
            raise InputError(
                f"pin {k} at {np.round(pts[k], 3).tolist()} is {d[k] * 100:.1f} cm from the garment "
                f"(at most {PIN_SNAP_M * 100:g} cm)",
                source,
            )
        mask[i] = True
    return mask


def rewrap(
    body,
    garment,
    strokes: Strokes,
    *,
    pins=(),
    params: RewrapParams | None = None,
    collider: BodyCollider | None = None,
    report: bool = True,
) -> Rewrapped:
    """Re-wrap part of a dressed `garment` (a DressedGarment or a GarmentFile read from its OBJ) on `body` with
    `strokes` ("target": "garment"), the `pins` (n, 3) points (snapped to the nearest garment vertices) held.
    See the module docstring for the steps. InputError for strokes of the wrong target, naming a missing piece,
    leaving their piece or crossing no triangle, 3D strokes off the garment, pins off the garment, and strokes that
    run only through pinned vertices. The input garment is not changed."""
    p = params or RewrapParams()
    if not isinstance(p, RewrapParams):
        raise InputError("params must be a RewrapParams")
    if not isinstance(strokes, Strokes) or not len(strokes):
        raise InputError("no strokes: a re-wrap needs at least one stroke pair", getattr(strokes, "source", None))
    src = strokes.source or None
    if strokes.target != "garment":
        raise InputError('these strokes dress a body ("target": "body"); a re-wrap needs "target": "garment"', src)
    t0 = time.perf_counter()
    g = as_garment_file(garment)
    g = dataclasses.replace(g, positions=np.array(g.positions, dtype=np.float64))
    mesh = body if isinstance(body, TriMesh) else body.mesh
    if collider is None:
        collider = BodyCollider.from_mesh(mesh) if isinstance(body, TriMesh) else BodyCollider.from_body(body)
    model = ClothModel.from_corners(
        g.faces,
        g.rest_shape,
        n_vertices=len(g.positions),
        params=offset_as_dressed(garment, p.cloth),
        face_layer=g.face_layer,
    )
    pinned = snap_pins(g, pins, source=src)
    if pinned.all():
        raise InputError("every garment vertex is pinned: nothing can move", src)
    body_surface = collider.surface_for(mesh)
    strokes = strokes_on_surface(strokes, Surface(TriMesh(g.positions, g.faces, name=g.name)))
    timings = {"prepare": time.perf_counter() - t0}

    # 1. Lay each stroke's triangles along its path on the body.
    t1 = time.perf_counter()
    acc = np.zeros_like(g.positions)
    cnt = np.zeros(len(g.positions))
    tracks = []
    for pair in strokes.pairs:
        ps = pair.pattern
        if ps.piece not in g.piece_names:
            raise InputError(
                f"stroke {pair.id}: pattern piece {ps.piece!r} is not in garment {g.name!r} "
                f"({', '.join(g.piece_names)})",
                src,
            )
        f0, f1 = (int(x) for x in g.piece_faces[g.piece_names.index(ps.piece)])
        tri = g.corner_uv[f0:f1] * 100.0  # (m, 3, 2) cm
        _, hit = segments_cross_triangles(np.asarray(ps.points, dtype=np.float64), tri)
        crossed = np.unique(hit)
        if not len(crossed):
            raise InputError(f"stroke {pair.id}: pattern stroke crosses no triangle of piece {ps.piece!r}", src)
        d1, d2 = tri[0, 1] - tri[0, 0], tri[0, 2] - tri[0, 0]
        side = 1.0 if d1[0] * d2[1] - d1[1] * d2[0] > 0 else -1.0
        corners_v = g.faces[f0 + crossed].reshape(-1)
        corners_uv = tri[crossed].reshape(-1, 2)
        vids, first = np.unique(corners_v, return_index=True)
        bpath, _ = body_path(body_surface, pair, src)
        x = lay_along(corners_uv[first], ps, side, bpath, body_surface, collider, lift_m=p.lift_m, fit_length=True)
        np.add.at(acc, vids, x)
        np.add.at(cnt, vids, 1.0)
        samples = resample_polyline(ps.points, RESIDUAL_SAMPLES)
        sf, bary = locate_in_triangles(tri[crossed], crossed, samples)
        tracks.append((pair.id, f0 + sf, bary, bpath))
    on_stroke = (cnt > 0) & ~pinned
    if not on_stroke.any():
        raise InputError("every stroke runs only through pinned vertices: nothing to re-wrap", src)
    target = g.positions.copy()
    target[on_stroke] = acc[on_stroke] / cnt[on_stroke, None]

    # 2. The rest follows its nearest stroke vertex, attenuated towards the pins.
    weight, nearest = follow_weights(model, on_stroke, pinned)
    shift = target - g.positions
    reach = nearest >= 0
    move = np.zeros_like(g.positions)
    move[reach] = weight[reach, None] * shift[nearest[reach]]
    move[pinned] = 0.0
    move[on_stroke] = shift[on_stroke]
    state = ClothState.new(model, g.positions + move)
    collide(model, state.holding(pinned | on_stroke), collider)
    timings["place"] = time.perf_counter() - t1

    # 3. Relax with the strokes and pins held, then settle with the pins only.
    t2 = time.perf_counter()
    log = StageLog("rewrap")
    close = CloseSettings(
        iterations=p.close_iterations, tolerance_m=0.0, cg_iterations=CG_ITERATIONS, contact_weight=p.contact_weight
    )
    run_stage(log, "closing", close_stage, model, state, collider, Closing(close), pinned=pinned | on_stroke)
    held = pinned | (on_stroke & (not p.release_strokes))
    # Edge-length restoration (as in the wrap) before the settle and after it. Only after: triangles along the
    # held stroke row folded against it and stayed so (kimono, hem turned up: 3); only before: the settle's
    # gravity sagged the cloth between sparse pins (median move at the chest 5.9 mm instead of < 5).
    lengths = Finishing(
        LengthSettings(sweeps=p.length_sweeps, chebyshev_rho=None, collide_every=3), close, search_afresh=False
    )
    run_stage(log, "restoring lengths", finish_stage, model, state, collider, lengths, pinned=held)
    if p.settle_iterations:
        # The Jacobi settle, not the wrap's global one: with the strokes held, the global settle left a triangle
        # folded against the held stroke row that the untangle cannot open (kimono, hem turned up: 1 vs 0).
        settling = Settling(SettleSettings(iterations=p.settle_iterations), model.params, p.contact_weight)
        run_stage(log, "settling", settle_stage, model, state, collider, settling, pinned=held)
        run_stage(log, "restoring lengths", finish_stage, model, state, collider, lengths, pinned=held)
    untangling = Untangling(p.untangle_rounds, iterations=p.untangle_iterations)
    run_stage(log, "untangling", untangle_stage, model, state, collider, untangling, pinned=held)
    folded = folded_faces(model, state)
    if p.untangle_rounds and folded.any():
        # A triangle folded against the held stroke row cannot open while the row holds it (the 1.5 cm kimono,
        # hem turned up: 2 left folded): let go of the stroke vertices of the folded triangles only, and retry.
        loose = np.zeros(model.n_vertices, dtype=bool)
        loose[model.faces[folded].reshape(-1)] = True
        held = held & ~(loose & ~pinned)
        run_stage(log, "untangling", untangle_stage, model, state, collider, untangling, pinned=held)

    def residual_of(positions: np.ndarray, _refined=None) -> np.ndarray:
        """(S,) metres: each pattern stroke's largest distance (on the garment) from its 3D stroke (the polish here
        does not refine, so the garment's faces hold the samples)."""
        return np.array(
            [
                polyline_distance(np.einsum("ij,ijk->ik", b, positions[g.faces[f]]), path).max()
                for _, f, b, path in tracks
            ]
        )

    timings.update(log.timings)
    if p.polish_rounds:
        t3 = time.perf_counter()
        # The wrap's last step, without refinement (the garment keeps its vertices); pins and held strokes held,
        # and not kept if it takes a stroke farther from its line.
        kept, polished = polish_step(
            model,
            state.holding(held),
            collider,
            PolishSettings(
                rounds=p.polish_rounds, untangle_rounds=p.untangle_rounds, untangle_iterations=p.untangle_iterations
            ),
            residual_of=residual_of,
        )
        if kept:
            state = polished.state
        timings["polishing"] = time.perf_counter() - t3
    state.positions[pinned] = g.positions[pinned]  # exactly still
    timings["relax"] = time.perf_counter() - t2
    timings["rewrap"] = time.perf_counter() - t0

    pos = state.positions
    residual = residual_of(pos)
    out = dataclasses.replace(g, positions=pos.copy())
    rep = None
    if report:
        rep = quality_report(
            pos,
            g.faces,
            mesh,
            rest_lengths=model.rest_lengths,
            rest_areas=model.rest_areas,
            pieces=(g.piece_names, g.piece_faces),
        )
    return Rewrapped(
        garment=out,
        pinned=pinned,
        strokes=on_stroke,
        moved_m=np.linalg.norm(pos - g.positions, axis=1),
        stroke_ids=[t[0] for t in tracks],
        stroke_residual_m=residual,
        report=rep,
        timings=timings,
    )
