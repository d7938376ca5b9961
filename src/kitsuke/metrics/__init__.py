"""Quality measures of a dressed garment (SPEC §6): penetration, strain, seam gap, inverted triangles, the order of
layered cloth, a garment's girth against the body's (`garment_girth`), and a JSON-ready report with pass/fail per
measure against the targets of issue 3.

    report = quality_report(positions, faces, body.mesh, rest_lengths=model.rest_lengths)
    report.ok, report.failures(), report.to_dict()
"""

from ._girth import Girth, WornLoop, body_section, garment_girth, tape_inside, worn_loop
from ._layers import layer_crossing_mm, wrong_side_mm
from ._measures import (
    COLLAPSE_RATIO,
    Penetration,
    SeamGap,
    Strain,
    inverted_triangles,
    mesh_edges,
    penetration,
    seam_gap,
    strain,
    vertex_strain,
)
from ._report import QualityReport, QualityTargets, quality_report

__all__ = [
    "COLLAPSE_RATIO",
    "Girth",
    "Penetration",
    "QualityReport",
    "QualityTargets",
    "SeamGap",
    "Strain",
    "WornLoop",
    "body_section",
    "garment_girth",
    "inverted_triangles",
    "layer_crossing_mm",
    "mesh_edges",
    "penetration",
    "quality_report",
    "seam_gap",
    "strain",
    "tape_inside",
    "vertex_strain",
    "worn_loop",
    "wrong_side_mm",
]
