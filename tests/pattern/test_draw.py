"""Pattern pictures: SVG structure and true size, PNG coverage and colours, textures through pattern coordinates."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np
import svgelements as se

from kitsuke.pattern import pattern_sheet, render_pattern_png, render_pattern_svg, save_pattern
from kitsuke.pattern._draw import PAPER, SEAM_COLOURS

NS = "{http://www.w3.org/2000/svg}"


def hex_rgb(h: str) -> np.ndarray:
    return np.array([int(h[i : i + 2], 16) for i in (1, 3, 5)])


def test_svg_is_true_size_and_labelled(hoody, tmp_path):
    text = render_pattern_svg(hoody)
    root = ET.fromstring(text)
    sheet = pattern_sheet(hoody)
    assert root.get("width") == f"{sheet.width:.3f}cm"
    assert root.get("viewBox").split()[2:] == [f"{sheet.width:.3f}", f"{sheet.height:.3f}"]
    labels = [t.text for t in root.iter(f"{NS}text")]
    for piece in hoody.pieces:
        assert piece.name in labels
    assert labels.count("0") >= len(hoody.pieces)  # every piece numbers its edges
    # Each piece's outline is drawn at true size: the polygon areas (cm^2) equal the piece areas.
    polys = [p for p in root.iter(f"{NS}polygon") if p.get("fill") == PAPER]
    areas = []
    for poly in polys:
        pts = np.array([xy.split(",") for xy in poly.get("points").split()], dtype=float)
        areas.append(0.5 * abs(pts[:, 0] @ np.roll(pts[:, 1], -1) - np.roll(pts[:, 0], -1) @ pts[:, 1]))
    np.testing.assert_allclose(sorted(areas), sorted(p.area for p in hoody.pieces), rtol=2e-3)
    # Both sides of every seam are drawn in the seam's colour.
    bands = [p.get("stroke") for p in root.iter(f"{NS}polyline")]
    for s in range(len(hoody.seams)):
        assert bands.count(SEAM_COLOURS[s % len(SEAM_COLOURS)]) >= 2
    path = tmp_path / "hoody.svg"
    save_pattern(hoody, path)
    assert len(list(se.SVG.parse(str(path)).elements())) > 50  # a standard parser reads it


def test_png_is_readable(hoody):
    img = render_pattern_png(hoody, max_px=900)
    assert max(img.shape[:2]) == 900 and img.dtype == np.uint8
    px = img.reshape(-1, 3).astype(int)
    paper = np.abs(px - hex_rgb(PAPER)).max(axis=1) <= 3
    assert 0.25 < paper.mean() < 0.75  # pieces cover a good part of the sheet
    dark = px.max(axis=1) < 80
    assert 0.005 < dark.mean() < 0.1  # outlines and text
    for s in range(len(hoody.seams)):
        colour = hex_rgb(SEAM_COLOURS[s % len(SEAM_COLOURS)])
        assert (np.abs(px - colour).max(axis=1) <= 12).sum() > 30, s


def test_textured_kimono_png(kimono):
    img = render_pattern_png(kimono, max_px=700, texture="asanoha", annotate=False)
    px = img.reshape(-1, 3).astype(int)
    # At this size the motif's lines blend into the indigo ground: pieces are blue, the sheet white.
    blue = (px[:, 2] - px[:, 0] > 25) & (px.max(axis=1) < 170)
    white = (px == 255).all(axis=1)
    assert blue.mean() > 0.15 and white.mean() > 0.3
    assert (np.abs(px - hex_rgb(PAPER)).max(axis=1) <= 3).mean() < 0.001  # no untextured piece
