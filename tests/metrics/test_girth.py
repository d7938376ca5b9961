"""A garment's girth against the body's: tubes of known rest and worn lengths round cylinders of known girth."""

from __future__ import annotations

import numpy as np
import pytest

from kitsuke.geometry import TriMesh
from kitsuke.metrics import garment_girth


def _cylinder(radius: float, centre=(0.0, 0.0), n: int = 64, y0: float = 0.6, y1: float = 1.2) -> TriMesh:
    """A closed cylinder (caps included) about the vertical through `centre` (x, z), metres."""
    a = 2 * np.pi * np.arange(n) / n
    ring = np.c_[centre[0] + radius * np.cos(a), np.zeros(n), centre[1] + radius * np.sin(a)]
    v = np.vstack([ring + [0, y0, 0], ring + [0, y1, 0], [[centre[0], y0, centre[1]], [centre[0], y1, centre[1]]]])
    i, j = np.arange(n), (np.arange(n) + 1) % n
    side = np.r_[np.c_[i, n + i, j], np.c_[j, n + i, n + j]]
    caps = np.r_[np.c_[np.full(n, 2 * n), i, j], np.c_[np.full(n, 2 * n + 1), n + j, n + i]]
    return TriMesh(v, np.r_[side, caps])


def _tube(radius: float, rest_width: float, n: int = 48, rings: int = 6, y0: float = 0.7, y1: float = 1.1,
          slit: bool = False):  # fmt: skip
    """An open tube of cloth round the vertical axis, cut from a rest_width x (y1 - y0) rectangle (metres): its
    positions, faces and rest corners. slit: its two long edges not sewn (a 1 cm gap between them)."""
    cols = n + 1 if slit else n
    gap = 0.01 / radius if slit else 0.0
    a = (2 * np.pi - gap) * np.arange(cols) / n
    ys = np.linspace(y0, y1, rings)
    pos = np.array([[radius * np.cos(t), y, radius * np.sin(t)] for y in ys for t in a])
    faces, corners = [], []
    for r in range(rings - 1):
        for c in range(n):
            c1 = c + 1 if slit else (c + 1) % n
            q = [r * cols + c, r * cols + c1, (r + 1) * cols + c, (r + 1) * cols + c1]
            u0, u1 = rest_width * c / n, rest_width * (c + 1) / n
            h0, h1 = ys[r] - y0, ys[r + 1] - y0
            faces += [[q[0], q[2], q[1]], [q[1], q[2], q[3]]]
            corners += [[[u0, h0], [u0, h1], [u1, h0]], [[u1, h0], [u0, h1], [u1, h1]]]
    return pos, np.array(faces), np.array(corners, dtype=np.float64)


def _polygon(radius: float, n: int) -> float:
    return 2 * n * radius * np.sin(np.pi / n)


def test_a_tube_cut_smaller_than_the_body_is_short_by_its_share():
    body = _cylinder(0.15)
    pos, faces, rest = _tube(0.152, rest_width=0.9 * _polygon(0.15, 64))
    g = garment_girth(pos, faces, rest, body, np.array([0.152, 0.93, 0.0]))
    assert g is not None
    assert g.body_m == pytest.approx(_polygon(0.15, 64), rel=1e-6)
    assert g.rest_m == pytest.approx(0.9 * _polygon(0.15, 64), rel=1e-6)
    assert g.worn_m == pytest.approx(_polygon(0.152, 48), rel=1e-6)
    assert g.short == pytest.approx(0.1, abs=1e-6)
    assert g.worn_m >= g.body_m  # cloth round the body is at least its tape girth


def test_a_loose_tube_is_not_short():
    body = _cylinder(0.15)
    pos, faces, rest = _tube(0.2, rest_width=1.3)
    g = garment_girth(pos, faces, rest, body, np.array([0.0, 1.0, 0.2]))
    assert g is not None and g.short < 0 and g.rest_m == pytest.approx(1.3)


def test_a_slit_of_a_centimetre_still_goes_round():
    body = _cylinder(0.15)
    pos, faces, rest = _tube(0.16, rest_width=0.9, slit=True)
    g = garment_girth(pos, faces, rest, body, np.array([-0.16, 0.9, 0.0]))
    assert g is not None and g.rest_m == pytest.approx(0.9, rel=1e-6)  # the gap adds no cloth


def test_round_two_legs_the_tape_spans_the_gap():
    legs = [_cylinder(0.07, (x, 0.0)) for x in (-0.1, 0.1)]
    body = TriMesh(np.vstack([m.vertices for m in legs]), np.r_[legs[0].faces, legs[1].faces + len(legs[0].vertices)])
    pos, faces, rest = _tube(0.2, rest_width=1.0)
    g = garment_girth(pos, faces, rest, body, np.array([0.2, 0.9, 0.0]))
    hull = 2 * 0.2 + _polygon(0.07, 64)  # two half circles and the two straight spans
    assert g is not None and g.body_m == pytest.approx(hull, rel=5e-3)


def test_cloth_that_does_not_go_round_has_no_girth():
    body = _cylinder(0.15)
    pos, faces, rest = _tube(0.16, rest_width=0.9)
    half = pos[faces][:, :, 2].min(axis=1) > 0.0  # the front half of the tube only: a panel
    g = garment_girth(pos, faces[half], rest[half], body, np.array([0.0, 0.9, 0.16]))
    assert g is None
    far = garment_girth(pos + [1.0, 0.0, 0.0], faces, rest, body, np.array([1.16, 0.9, 0.0]))
    assert far is None  # a loop round no part of the body


def test_the_misses_say_a_pattern_cut_smaller_than_the_body():
    """A tube 10 % shorter than the body round it, worn stretched: the strain miss says the pattern is cut smaller
    than the body there; a loose one's miss does not."""
    from types import SimpleNamespace

    from kitsuke.dressing import target_misses
    from kitsuke.metrics import mesh_edges, quality_report

    body = _cylinder(0.15)
    for width, said in ((0.9 * _polygon(0.15, 64), True), (1.2, False)):
        pos, faces, rest = _tube(0.152, rest_width=width)
        edges = mesh_edges(faces)
        # each edge's rest length from its faces' rest corners (the tube's rest is a flat rectangle)
        lengths = {}
        for f, c in zip(faces, rest, strict=True):
            for k in range(3):
                a, b = f[k], f[(k + 1) % 3]
                lengths[(min(a, b), max(a, b))] = float(np.linalg.norm(c[k] - c[(k + 1) % 3]))
        rest_lengths = np.array([lengths[(min(a, b), max(a, b))] for a, b in edges])
        report = quality_report(pos, faces, body, rest_lengths=rest_lengths)
        worst = pos[edges[report.strain_worst_edges[0]]].mean(axis=0)
        garment = SimpleNamespace(
            report=report,
            girth=garment_girth(pos, faces, rest, body, worst),
            stroke_ids=[],
            stroke_residual_m=np.zeros(0),
        )
        strain_line = [m for m in target_misses(garment) if m.startswith("max edge strain")]
        assert strain_line, target_misses(garment)  # stretched or squeezed round the body either way
        assert ("cut 10 % smaller than the body" in strain_line[0]) is said, strain_line


def test_a_body_without_thickness_inside_the_loop_has_no_girth():
    """A loop round a flat sheet (its cut is a line: no area for a tape to go round) gives none, not a division
    by zero."""
    corners = np.array([[-0.1, 0.6, 0.0], [0.1, 0.6, 0.0], [0.1, 1.2, 0.0], [-0.1, 1.2, 0.0]])
    sheet = TriMesh(corners, np.array([[0, 1, 2], [0, 2, 3]]))
    pos, faces, rest = _tube(0.16, rest_width=0.9)
    assert garment_girth(pos, faces, rest, sheet, np.array([0.16, 0.9, 0.0])) is None
