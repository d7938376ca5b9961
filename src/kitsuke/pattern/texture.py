"""Procedural traditional Japanese textile repeats for kimono, drawn with vectorised numpy (anti-aliased).

Motifs
------
- ``"asanoha"`` (麻の葉, hemp leaf): a lattice of equilateral triangles with side `repeat_cm`; every triangle edge is
  drawn and every triangle is split into three by lines from its corners to its centre, which makes the six-pointed
  leaves around each lattice point. Period: (repeat_cm, repeat_cm * sqrt(3)).
- ``"seigaiha"`` (青海波, blue ocean waves): rows of concentric-circle fans of radius `repeat_cm`, each row half a
  fan across from the next, lower rows in front. Period: (2 * repeat_cm, repeat_cm).

How a texture maps onto pattern pieces (UVs)
--------------------------------------------
The texture is a function of the *pattern* position in centimetres, the same on every piece, so the motif has the
same size everywhere. A seamless tile covers exactly `texture_tile_size_cm(motif, repeat_cm)` = (Tw, Th) cm; a
mesh vertex at pattern position (x, y) cm gets ``uv = (x / Tw, y / Th)`` and the texture is sampled with REPEAT
wrapping (glTF's default). v follows the OBJ/OpenGL convention: v = 0 is the bottom row of the image, so the image
is drawn with pattern y pointing up. `kimono_texture(size_cm=..., origin_cm=...)` renders any region of the same
infinite design directly (for flat-pattern pictures), consistent with the tile.

Edges are anti-aliased analytically: each pixel's coverage comes from its distance to the nearest line (or ring
edge), ramped over one pixel, so the result is crisp at any resolution.
"""

from __future__ import annotations

import math
from typing import Literal

import numpy as np

from ..errors import InputError

Motif = Literal["asanoha", "seigaiha"]
MOTIFS = ("asanoha", "seigaiha")

#: Colour schemes: (ground, ink) as RGB 0..255.
PALETTES: dict[str, tuple[tuple[int, int, int], tuple[int, int, int]]] = {
    "indigo": ((28, 52, 94), (236, 228, 209)),  # ai-zome blue with unbleached white
    "crimson": ((150, 32, 44), (236, 196, 120)),  # beni red with gold
    "sakura": ((240, 212, 218), (176, 74, 98)),  # pale pink with deep rose
    "matcha": ((84, 110, 64), (228, 222, 190)),
}


def texture_tile_size_cm(motif: Motif = "asanoha", repeat_cm: float = 3.0) -> tuple[float, float]:
    """(width, height) in cm of one seamless tile of the motif at this repeat size."""
    _check(motif, repeat_cm)
    if motif == "asanoha":
        return repeat_cm, repeat_cm * math.sqrt(3.0)
    return 2.0 * repeat_cm, repeat_cm


def _check(motif: str, repeat_cm: float) -> None:
    if motif not in MOTIFS:
        raise InputError(f"unknown motif {motif!r} (use {', '.join(MOTIFS)})")
    if not (math.isfinite(repeat_cm) and repeat_cm > 0):
        raise InputError("repeat_cm must be a positive number of centimetres")


def _segment_distance(px: np.ndarray, py: np.ndarray, segs: np.ndarray) -> np.ndarray:
    """Distance of points (px, py) (any shape) to the nearest of segments (k, 4) [x0, y0, x1, y1]."""
    best = np.full(px.shape, np.inf)
    for x0, y0, x1, y1 in segs:
        dx, dy = x1 - x0, y1 - y0
        t = np.clip(((px - x0) * dx + (py - y0) * dy) / (dx * dx + dy * dy), 0.0, 1.0)
        best = np.minimum(best, np.hypot(px - (x0 + t * dx), py - (y0 + t * dy)))
    return best


def _asanoha_ink(x: np.ndarray, y: np.ndarray, a: float, line_cm: float, px_cm: float) -> np.ndarray:
    """Ink coverage 0..1 of the asanoha design at pattern points (x, y) cm."""
    h = a * math.sqrt(3.0) / 2.0
    # Lattice basis b1 = (a, 0), b2 = (a/2, h); fold every point into the cell spanned by them. The cell's border
    # is drawn (lattice edges), so the nearest line always belongs to the cell's own two triangles.
    v = y / h
    u = x / a - 0.5 * v
    fu, fv = u - np.floor(u), v - np.floor(v)
    qx, qy = fu * a + fv * 0.5 * a, fv * h
    p0, p1, p2, p3 = (0.0, 0.0), (a, 0.0), (0.5 * a, h), (1.5 * a, h)
    segs = []
    for tri in ((p0, p1, p2), (p1, p3, p2)):
        c = (sum(p[0] for p in tri) / 3.0, sum(p[1] for p in tri) / 3.0)
        for i in range(3):
            s, e = tri[i], tri[(i + 1) % 3]
            segs.append((*s, *e))  # triangle edge
            segs.append((*s, *c))  # corner to centre
    d = _segment_distance(qx, qy, np.array(segs))
    return np.clip(0.5 + (0.5 * line_cm - d) / px_cm, 0.0, 1.0)


def _seigaiha_ink(x: np.ndarray, y: np.ndarray, r: float, line_cm: float, px_cm: float, rings: int = 4) -> np.ndarray:
    """Ink coverage 0..1 of the seigaiha design at pattern points (x, y) cm."""
    # Fan centres: row j at height j * r / 2, x at 2 r i + r (j mod 2). A lower row is in front, so a point takes the
    # lowest row whose fan (disk of radius r) contains it.
    row_h = 0.5 * r
    j0 = np.floor(y / row_h).astype(np.int64)
    ink = np.zeros(x.shape)
    decided = np.zeros(x.shape, dtype=bool)
    for dj in range(-2, 1):  # the rows below and at the point's row; lowest first
        j = j0 + dj
        cy = j * row_h
        off = r * (j % 2)
        cx = 2.0 * r * np.round((x - off) / (2.0 * r)) + off
        dist = np.hypot(x - cx, y - cy)
        inside = (dist <= r) & (y >= cy) & ~decided
        # Concentric rings: ink lines at radii k r / rings (k = 1..rings), the innermost a filled dot.
        spacing = r / rings
        k = np.clip(np.round(dist / spacing), 1, rings)
        d_ring = np.abs(dist - k * spacing)
        d_line = np.minimum(d_ring, np.maximum(dist - 0.35 * spacing, 0.0))
        cover = np.clip(0.5 + (0.5 * line_cm - d_line) / px_cm, 0.0, 1.0)
        # The fan's own rim stays visible against the fans behind it.
        ink = np.where(inside, cover, ink)
        decided |= inside
    return ink


def kimono_texture(
    *,
    motif: Motif = "asanoha",
    repeat_cm: float = 3.0,
    px_per_cm: float = 40.0,
    size_cm: tuple[float, float] | None = None,
    origin_cm: tuple[float, float] = (0.0, 0.0),
    palette: str = "indigo",
    line_cm: float | None = None,
) -> np.ndarray:
    """Draw a traditional textile repeat.

    Parameters
    ----------
    motif : "asanoha" or "seigaiha".
    repeat_cm : the motif's size, cm (asanoha: triangle side; seigaiha: fan radius).
    px_per_cm : resolution.
    size_cm : (width, height) of the region to draw, cm. None: exactly one seamless tile,
        `texture_tile_size_cm(motif, repeat_cm)`, whose pixel size is rounded and the design scaled to fit, so that
        repeating it leaves no seam.
    origin_cm : pattern position (x, y) cm of the region's bottom-left corner (ignored for a tile).
    palette : a key of PALETTES.
    line_cm : ink line width, cm (default: repeat_cm / 22).

    Returns
    -------
    (H, W, 3) uint8 RGB image; row 0 is the top (largest pattern y).
    """
    _check(motif, repeat_cm)
    if palette not in PALETTES:
        raise InputError(f"unknown palette {palette!r} (use {', '.join(PALETTES)})")
    if not (math.isfinite(px_per_cm) and px_per_cm > 0):
        raise InputError("px_per_cm must be positive")
    line = repeat_cm / 22.0 if line_cm is None else float(line_cm)
    if size_cm is None:
        tw, th = texture_tile_size_cm(motif, repeat_cm)
        w, h = max(8, round(tw * px_per_cm)), max(8, round(th * px_per_cm))
        sx, sy = tw / w, th / h  # cm per pixel along each axis (the design is stretched by < 1 pixel to fit)
        x0, y0 = 0.0, 0.0
    else:
        width, height = (float(v) for v in size_cm)
        if not (width > 0 and height > 0 and math.isfinite(width * height)):
            raise InputError("size_cm must be two positive numbers")
        w, h = max(1, math.ceil(width * px_per_cm)), max(1, math.ceil(height * px_per_cm))
        if w * h > 80_000_000:
            raise InputError(f"texture of {w}x{h} pixels is too large; lower px_per_cm")
        sx = sy = 1.0 / px_per_cm
        x0, y0 = (float(v) for v in origin_cm)
    ground, ink_rgb = (np.array(c, dtype=np.float64) for c in PALETTES[palette])
    out = np.empty((h, w, 3), dtype=np.uint8)
    cols = x0 + (np.arange(w) + 0.5) * sx
    px_cm = math.sqrt(sx * sy)
    for r0 in range(0, h, 512):  # rows in blocks: bounded memory for large regions
        rows = np.arange(r0, min(h, r0 + 512))
        ys = y0 + (h - rows - 0.5) * sy  # row 0 is the top
        x, y = np.meshgrid(cols, ys)
        if motif == "asanoha":
            cover = _asanoha_ink(x, y, repeat_cm, line, px_cm)
        else:
            cover = _seigaiha_ink(x, y, repeat_cm, line, px_cm)
        rgb = ground + cover[..., None] * (ink_rgb - ground)
        out[r0 : r0 + len(rows)] = np.clip(np.round(rgb), 0, 255).astype(np.uint8)
    return out


def texture_uv(points_cm: np.ndarray, motif: Motif = "asanoha", repeat_cm: float = 3.0) -> np.ndarray:
    """UVs (n, 2) of pattern points (n, 2) cm for the seamless tile of this motif (REPEAT wrapping, v up)."""
    tw, th = texture_tile_size_cm(motif, repeat_cm)
    return np.asarray(points_cm, dtype=np.float64).reshape(-1, 2) / np.array([tw, th])
