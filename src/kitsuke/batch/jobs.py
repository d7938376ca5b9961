"""The dress job: what `kitsuke dress` does for one manifest row, in a worker, by the same library calls.

A job on (body, pattern, strokes or `suggest`) runs `suggest_strokes` where asked (its strokes written as
`kitsuke strokes suggest` writes them, and read back, so the garment is the one the two commands make), perturbs
them where asked (`perturb_strokes`, seeded: robustness runs), then `check_strokes` and `wrap` with
`DressOptions.wrap_params`, and writes the outputs `kitsuke dress` writes. Its status: ok (every target met),
out_of_target (written, the missed targets are its reason), refused (InputError), failed (ComputationError: one
line naming the stage).
"""

from __future__ import annotations

import json
import tempfile
from collections.abc import Hashable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import ComputationError, InputError
from .manifest import BodySource, Job
from .outcome import FAILED, OK, OUT_OF_TARGET, REFUSED, Derived, Outcome

#: The outputs of a done job, in OUTDIR/<job id>/ (the OBJ and report always; the GLB and PNG as the job says).
GLB, OBJ, REPORT, PNG, STROKES = "garment.glb", "garment.obj", "report.json", "views.png", "strokes.json"


@dataclass(frozen=True)
class DressKind:
    """`kitsuke batch dress`: a manifest's dress jobs (see the module docstring)."""

    name: str = "dress"

    def inputs(self, job: Job) -> dict[str, Hashable]:
        keys: dict[str, Hashable] = {"body": job.body, "pattern": ("pattern", job.pattern)}
        if job.strokes is not None:
            keys["strokes"] = ("strokes", job.strokes)
        return keys

    def load(self, key: Hashable) -> Any:
        from ..dressing import read_strokes
        from ..pattern import load_pattern

        if isinstance(key, BodySource):
            return load_body_source(key)
        what, path = key  # type: ignore[misc]
        return load_pattern(path) if what == "pattern" else read_strokes(path)

    def timeout_s(self, job: Job) -> float | None:
        return job.timeout_s

    def warm(self) -> None:
        """Load (or, the first time after an install, compile: ~20 s) the wrap's numba kernels: a kimono at 10 cm
        edges on the default body goes through every stage (capsules, layers, polish) in ~1-2 s with numba's cache
        warm (at 6 cm, 3-5 s: the kernels are the same whatever the size)."""
        from ..body import default_body
        from ..dressing import load_packaged_strokes, wrap
        from ..dressing.options import DressOptions
        from ..pattern import default_kimono

        body, kimono = default_body(), default_kimono()
        params = DressOptions(edge_length=10.0).wrap_params(body, kimono)
        wrap(body, kimono, load_packaged_strokes("kimono_default"), params=params, check=False)

    def run(self, job: Job, inputs: dict[str, Any], derived: Derived) -> Outcome:
        from ..cloth import BodyCollider
        from ..dressing import (
            check_strokes,
            perturb_strokes,
            strokes_from_dict,
            strokes_to_json,
            suggest_strokes,
            wrap,
        )
        from ..dressing.suggest import SuggestParams

        body, pattern = inputs["body"], inputs["pattern"]
        collider = derived("body", BodyCollider.from_body)
        files: dict[str, bytes] = {}
        try:
            if job.strokes is None:
                params = SuggestParams() if job.min_area is None else SuggestParams(min_area_share=job.min_area)
                suggested = suggest_strokes(body, pattern, params=params, surface=collider.surface)
                suggested.meta["body"] = job.body.path  # as `kitsuke strokes suggest` notes it
                text = strokes_to_json(suggested)
                files[STROKES] = text.encode("utf-8")
                strokes = strokes_from_dict(json.loads(text))
            else:
                strokes = inputs["strokes"]
            if job.perturb is not None:
                strokes = perturb_strokes(strokes, collider.surface, np.random.default_rng(job.perturb))
                files[STROKES] = strokes_to_json(strokes).encode("utf-8")
            check_strokes(strokes, pattern)
            garment = wrap(body, pattern, strokes, params=job.options.wrap_params(body, pattern), collider=collider)
        except InputError as e:
            return Outcome(REFUSED, str(e))
        except ComputationError as e:
            return Outcome(FAILED, str(e))
        misses = target_misses_of(garment, job.targets)
        files.update(_outputs(garment, body, job))
        return Outcome(OUT_OF_TARGET if misses else OK, "; ".join(misses), measures=measures(garment), files=files)


def load_body_source(source: BodySource):
    """The Body of a manifest's body column: the packaged body for `default`, else the file read with its options."""
    from ..body import default_body, load_body

    if source.path == "default":
        return default_body()
    return load_body(source.path, units=source.units, up=source.up, facing=source.facing, group=source.group)


def target_misses_of(garment, targets: str) -> list[str]:
    """The quality targets `garment` misses: QualityTargets() for "standard", .robust() for "robust"."""
    from ..dressing import target_misses
    from ..metrics import QualityTargets

    return target_misses(garment, QualityTargets.robust() if targets == "robust" else QualityTargets())


def measures(garment) -> dict[str, Any]:
    """The summary's columns of a dressed garment (strain in %, distances in mm, counts, the wrap's seconds)."""
    r = garment.report
    return {
        "vertices": garment.n_vertices,
        "strain_mean_pct": round(100 * r.strain_mean, 4),
        "strain_max_pct": round(100 * r.strain_max, 3),
        "deepest_mm": round(r.penetration_deepest_mm, 3),
        "inside": r.penetration_count,
        "seam_gap_mm": round(r.seam_gap_mm, 3),
        "inverted": r.inverted_count,
        "stroke_mm": round(garment.max_stroke_residual_m * 1e3, 2),
        "loose_strokes": len(garment.loose_strokes),
        "wrap_s": round(garment.timings.get("wrap", 0.0), 3),
    }


def _outputs(garment, body, job: Job) -> dict[str, bytes]:
    """The job's output files as bytes, written by the functions `kitsuke dress` writes with (to a scratch
    folder, read back: the driver writes them into the job's folder)."""
    from ..dressing.export import write_garment_outputs

    with tempfile.TemporaryDirectory(prefix="kitsuke-job-") as tmp:
        paths = {
            name: Path(tmp) / name
            for name, wanted in ((GLB, job.glb), (OBJ, True), (REPORT, True), (PNG, job.png))
            if wanted
        }
        write_garment_outputs(garment, body.mesh, paths.get(GLB), paths[OBJ], paths[REPORT], paths.get(PNG))
        return {name: p.read_bytes() for name, p in paths.items()}
