"""The calibration job: what `kitsuke kimono calibrate` does for one manifest row, in a worker, by the same library
calls: the kimono (the default one or a pattern of other sizes) dressed on the default body for simulation, then
E(θ) and A by simulated leg spreads. Each job runs its spreads one after another: the batch's workers are the
parallelism. Outputs: constraints.json (the table `pose correct --constraints` reads) and e.png (its polar plot
against the geometric estimate). Status: ok (a table), refused (not a kimono), failed (the dressing or the
simulation failed: one line naming the stage)."""

from __future__ import annotations

import functools
import tempfile
from collections.abc import Hashable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..errors import ComputationError, InputError
from .manifest import CalibrateJob
from .outcome import FAILED, OK, REFUSED, Derived, Outcome

TABLE, PLOT = "constraints.json", "e.png"


@functools.cache
def _body():  # noqa: ANN202 - the default Body, loaded once per worker
    from ..body import default_body

    return default_body()


@dataclass(frozen=True)
class CalibrateKind:
    """`kitsuke batch calibrate`: a manifest's kimono calibration jobs (see the module docstring)."""

    name: str = "calibrate"

    def inputs(self, job: CalibrateJob) -> dict[str, Hashable]:
        return {"pattern": ("kimono", job.pattern)}

    def load(self, key: Hashable) -> Any:
        from ..dressing.kimono import check_kimono
        from ..pattern import default_kimono, load_pattern

        _, path = key  # type: ignore[misc]
        if path == "default":
            return default_kimono()
        pattern = load_pattern(path)
        check_kimono(pattern)
        return pattern

    def timeout_s(self, job: CalibrateJob) -> float | None:
        return job.timeout_s

    def warm(self) -> None:
        """The wrap's kernels (`DressKind.warm`) and the dynamic solver's (a step of a cloth tube round the moving
        default body), from numba's cache or compiled the first time after an install."""
        import numpy as np

        from ..cloth import BodyCollider, ClothModel, ClothState, MovingBody, grid_tube, step
        from .jobs import DressKind

        DressKind().warm()
        body = _body()
        faces, corners, _ = grid_tube(24, 4, 0.05)
        angle = np.arange(24) / 24 * 2 * np.pi
        ring = np.column_stack([0.2 * np.cos(angle), np.zeros(24), 0.2 * np.sin(angle)])
        tube = np.concatenate([ring + [0.0, 1.0 - 0.05 * j, 0.0] for j in range(4)])
        model = ClothModel.from_corners(faces, corners)
        moving = MovingBody.of(BodyCollider.from_body(body))
        moving.move_to(moving.ends, body.mesh.vertices)
        step(model, ClothState.new(model, tube), moving, 1 / 30)

    def run(self, job: CalibrateJob, inputs: dict[str, Any], derived: Derived) -> Outcome:
        from ..pose import packaged_constraints, write_constraints
        from ..tryon import default_simulation_kimono
        from ..tryon.calibrate import CalibrationSettings, calibrate, plot_constraints

        body, pattern = _body(), inputs["pattern"]
        label = "kimono standard" if job.pattern == "default" else f"kimono {Path(job.pattern).stem}"
        try:
            garment = default_simulation_kimono(body, pattern)
            result = calibrate(garment, body, settings=CalibrationSettings(theta_step_deg=job.step_deg, workers=1))
        except InputError as e:
            return Outcome(REFUSED, str(e))
        except ComputationError as e:
            return Outcome(FAILED, str(e))
        table = result.table
        with tempfile.TemporaryDirectory(prefix="kitsuke-job-") as tmp:
            paths = {TABLE: Path(tmp) / TABLE, PLOT: Path(tmp) / PLOT}
            write_constraints(table, paths[TABLE])
            plot_constraints(table, paths[PLOT], against=packaged_constraints("geometric"), title=label)
            files = {name: p.read_bytes() for name, p in paths.items()}
        measures: dict[str, Any] = {"calibrate_s": round(result.seconds, 1)}
        for pair in ("knee", "ankle"):
            lim = table.pair(pair)
            measures[f"{pair}_e_min_cm"] = round(100 * float(lim.max_distance_m.min()), 1)
            measures[f"{pair}_e_max_cm"] = round(100 * float(lim.max_distance_m.max()), 1)
            measures[f"{pair}_area_cm2"] = round(1e4 * lim.area_m2, 0)
        return Outcome(OK, "", measures=measures, files=files)
