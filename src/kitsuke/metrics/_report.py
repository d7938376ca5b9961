"""The quality report of a dressed garment: all measures of SPEC §6 against the targets of issue 3."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import asdict, dataclass, field

import numpy as np

from ..errors import InputError
from ..geometry import TriMesh
from ._measures import _faces, _points, inverted_triangles, mesh_edges, penetration, seam_gap, strain


@dataclass(frozen=True)
class QualityTargets:
    """Pass/fail limits (issue 3, item 6).

    penetration_mm : no cloth vertex deeper inside the body than this. max_strain, mean_strain : edge strain
    limits (fractions: 0.05 = 5 %). seam_gap_mm : largest gap between seam sides. inverted : most inverted
    triangles allowed. stroke_residual_mm : every pattern stroke lies within this of its body stroke once
    dressed (`kitsuke.dressing.target_misses`; the quality report itself knows no strokes).
    """

    penetration_mm: float = 2.0
    max_strain: float = 0.05
    mean_strain: float = 0.01
    seam_gap_mm: float = 3.0
    inverted: int = 0
    stroke_residual_mm: float = 10.0

    @classmethod
    def robust(cls) -> QualityTargets:
        """The targets for garments and strokes nobody tuned for (benchmarks/bench_corpus.py): max strain 10 %."""
        return cls(max_strain=0.10)

    @classmethod
    def motion(cls) -> QualityTargets:
        """The targets of each frame of a simulated garment on a moving body (`kitsuke.tryon`): no vertex more
        than 5 mm inside (the skin itself moves by linear blend skinning and folds at the joints), max strain
        10 %."""
        return cls(penetration_mm=5.0, max_strain=0.10)


@dataclass
class QualityReport:
    """Measures of one dressed garment and whether each meets its target. `to_dict()` is JSON-ready.

    penetration_count : vertices deeper than targets.penetration_mm inside the body. penetration_deepest_mm : the
    deepest vertex inside (mm, 0 if none). strain_mean, strain_max : edge strain (fractions). strain_worst_edges :
    indices into the edges, worst first. seam_gap_mm : largest gap over all seams, seam_gaps_mm per seam.
    inverted_count, inverted_faces (the first 20). strain_worst_at, inverted_at : where the worst edge and the
    first inverted triangle lie ("piece NAME at (x, y, z) m"; None without pieces, see `quality_report`), so a
    report that fails says where to look. passed : {measure: bool}; ok : all passed.
    """

    n_vertices: int
    n_faces: int
    penetration_count: int
    penetration_deepest_mm: float
    strain_mean: float
    strain_max: float
    strain_stretched: float
    strain_compressed: float
    strain_worst_edges: list[int]
    seam_gap_mm: float
    seam_gaps_mm: list[float]
    inverted_count: int
    inverted_faces: list[int]
    targets: QualityTargets = field(default_factory=QualityTargets)
    passed: dict[str, bool] = field(default_factory=dict)
    strain_worst_at: str | None = None
    inverted_at: str | None = None

    @property
    def ok(self) -> bool:
        return all(self.passed.values())

    def judge(self, targets: QualityTargets) -> dict[str, bool]:
        """{measure: met} of these measures against `targets` (the report's own: `passed`)."""
        return {
            "penetration": self.penetration_deepest_mm <= targets.penetration_mm,
            "max_strain": self.strain_max <= targets.max_strain,
            "mean_strain": self.strain_mean <= targets.mean_strain,
            "seam_gap": self.seam_gap_mm <= targets.seam_gap_mm,
            "inverted": self.inverted_count <= targets.inverted,
        }

    def failures(self, targets: QualityTargets | None = None) -> list[str]:
        """One line per measure that missed its target (the report's own, or `targets`), saying by how much (and
        where, when the report knows)."""
        t = targets or self.targets
        passed = self.passed if targets is None else self.judge(targets)
        worst = "" if self.strain_worst_at is None else f" (worst on {self.strain_worst_at})"
        first = "" if self.inverted_at is None else f" (first on {self.inverted_at})"
        lines = {
            "penetration": f"{self.penetration_count} vertices deeper than {t.penetration_mm} mm inside the body "
            f"(deepest {self.penetration_deepest_mm:.1f} mm)",
            "max_strain": f"max edge strain {100 * self.strain_max:.1f} % > {100 * t.max_strain:.1f} %{worst}",
            "mean_strain": f"mean edge strain {100 * self.strain_mean:.2f} % > {100 * t.mean_strain:.2f} %",
            "seam_gap": f"seam gap {self.seam_gap_mm:.1f} mm > {t.seam_gap_mm} mm",
            "inverted": f"{self.inverted_count} inverted triangles > {t.inverted}{first}",
        }
        return [lines[k] for k, v in passed.items() if not v]

    def to_dict(self) -> dict:
        d = asdict(self)
        d["ok"] = self.ok
        return d


def quality_report(
    positions: np.ndarray,
    faces: np.ndarray,
    body: TriMesh,
    *,
    rest_lengths: np.ndarray,
    edges: np.ndarray | None = None,
    seams: Sequence[tuple[np.ndarray, np.ndarray]] = (),
    rest_areas: np.ndarray | None = None,
    targets: QualityTargets | None = None,
    pieces: tuple[Sequence[str], np.ndarray] | None = None,
) -> QualityReport:
    """All quality measures of cloth at `positions` (V, 3) metres with `faces` (F, 3) on `body`.

    rest_lengths : (E,) metres, per edge of `edges` (default `mesh_edges(faces)`, the order ClothModel uses).
    seams : pairs of vertex index arrays (see `seam_gap`); none for a sewn mesh that shares seam vertices.
    rest_areas : (F,) square metres, to count collapsed triangles as inverted (see `inverted_triangles`).
    pieces : (names (P,), piece_faces (P, 2) int64 [start, stop) face ranges), to say on which piece, and where,
        the worst edge and the first inverted triangle lie.
    """
    t = targets or QualityTargets()
    pos = _points(positions, "positions")
    f = _faces(faces, len(pos))
    e = mesh_edges(f) if edges is None else np.asarray(edges)
    if len(np.asarray(rest_lengths)) != len(e):
        raise InputError(f"rest_lengths has {len(np.asarray(rest_lengths))} entries for {len(e)} edges")
    pen = penetration(pos, body, threshold_m=t.penetration_mm / 1e3)
    st = strain(pos, e, rest_lengths)
    gap = seam_gap(pos, seams)
    inv = np.flatnonzero(inverted_triangles(pos, f, rest_areas=rest_areas))
    report = QualityReport(
        n_vertices=len(pos),
        n_faces=len(f),
        penetration_count=pen.count,
        penetration_deepest_mm=round(pen.deepest_mm, 3),
        strain_mean=round(st.mean, 6),
        strain_max=round(st.max, 6),
        strain_stretched=round(st.stretched, 6),
        strain_compressed=round(st.compressed, 6),
        strain_worst_edges=[int(i) for i in st.worst_edges],
        seam_gap_mm=round(gap.max_mm, 3),
        seam_gaps_mm=[round(g, 3) for g in gap.per_seam_mm],
        inverted_count=len(inv),
        inverted_faces=[int(i) for i in inv[:20]],
        targets=t,
    )
    if pieces is not None and len(f):
        names, ranges = pieces
        ranges = np.asarray(ranges)
        if ranges.shape != (len(names), 2) or not len(names) or ranges[-1, 1] != len(f):
            raise InputError(f"pieces must name {len(names)} [start, stop) face ranges ending at {len(f)} faces")
        piece_of = ranges[:, 1]

        def where(face: int, point: np.ndarray) -> str:
            name = names[min(int(np.searchsorted(piece_of, face, side="right")), len(names) - 1)]
            return f"piece {name} at ({point[0]:.3f}, {point[1]:.3f}, {point[2]:.3f}) m"

        if len(st.worst_edges):
            a, b = e[st.worst_edges[0]]
            face = int(np.flatnonzero((f == a).any(axis=1) & (f == b).any(axis=1))[0])
            report.strain_worst_at = where(face, (pos[a] + pos[b]) / 2)
        if len(inv):
            report.inverted_at = where(int(inv[0]), pos[f[inv[0]]].mean(axis=0))
    report.passed = {
        "penetration": pen.count == 0,
        "max_strain": st.max <= t.max_strain,
        "mean_strain": st.mean <= t.mean_strain,
        "seam_gap": gap.max_mm <= t.seam_gap_mm,
        "inverted": len(inv) <= t.inverted,
    }
    return report
