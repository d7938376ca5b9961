"""Pattern pictures: a flat layout of the pieces drawn as SVG (true size, cm) or PNG (Pillow, anti-aliased).

The picture is built once as a list of simple primitives in sheet centimetres (y down) and then written by either
backend, so the SVG and the PNG show the same thing:

- every piece upright (its y up), filled (paper colour or a textile texture), outlined, its name and area at the
  roomiest point inside it;
- every edge's index at its midpoint, just inside the piece;
- every seam in its own colour: a band along both of its edges, the seam number on each band, and a dot near the
  ends that meet (edge a's start and its partner on b), so the sewing direction can be read;
- a title with the counts, a 10 cm scale bar, and a seam legend (number, edges, lengths).
"""

from __future__ import annotations

import base64
import io
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from html import escape

import numpy as np

from . import _geometry as geo
from ._types import Pattern, Piece

SEAM_COLOURS = [
    "#d1495b", "#2e86ab", "#3a9d5d", "#e08e0b", "#7b4fa3", "#1b998b", "#c2185b", "#5c6bc0",
    "#8d6e63", "#43a047", "#f4511e", "#00838f", "#6d4c41", "#ad1457", "#3949ab", "#7cb342",
]  # fmt: skip
PAPER = "#f6f1e7"
INK = "#2b2b2b"
MUTED = "#7a7368"


@dataclass
class TextureFill:
    """A texture for piece fills: `render(origin_cm, size_cm, px_per_cm) -> (H, W, 3) uint8` draws any region of
    pattern coordinates (row 0 at the top); `tile` (H, W, 3) uint8 covering `tile_cm` repeats for SVG."""

    render: Callable[[tuple[float, float], tuple[float, float], float], np.ndarray]
    tile: np.ndarray
    tile_cm: tuple[float, float]


@dataclass
class Poly:
    points: np.ndarray  # (n, 2) sheet cm
    fill: str | None = None
    stroke: str | None = None
    width: float = 0.0
    closed: bool = True
    texture: TextureFill | None = None
    texture_origin: tuple[float, float, float, float] | None = None  # piece (minx, miny, maxx, maxy) and offset
    opacity: float = 1.0


@dataclass
class Dot:
    centre: tuple[float, float]
    radius: float
    fill: str
    stroke: str | None = None
    width: float = 0.0


@dataclass
class Label:
    pos: tuple[float, float]
    text: str
    size: float  # cm (cap height ~ 0.7 size)
    colour: str = INK
    anchor: str = "middle"  # middle | start
    bold: bool = False
    halo: bool = False
    vertical: bool = False  # turned 90° counter-clockwise (reads upwards), for tall narrow pieces


@dataclass
class Sheet:
    width: float
    height: float
    items: list = field(default_factory=list)
    texture_offsets: dict = field(default_factory=dict)


def _pole(poly: np.ndarray, step_frac: float = 0.04) -> tuple[np.ndarray, float]:
    """A point well inside the polygon (the grid point farthest from the boundary) and its distance."""
    lo, hi = poly.min(axis=0), poly.max(axis=0)
    step = max(float((hi - lo).max()) * step_frac, 1e-6)
    xs = np.arange(lo[0] + step / 2, hi[0], step)
    ys = np.arange(lo[1] + step / 2, hi[1], step)
    gx, gy = np.meshgrid(xs, ys)
    p = np.stack([gx.ravel(), gy.ravel()], axis=-1)
    a, b = poly, np.roll(poly, -1, axis=0)
    # even-odd inside test and distance to the boundary, vectorised over points x segments
    cond = (a[None, :, 1] > p[:, None, 1]) != (b[None, :, 1] > p[:, None, 1])
    xint = a[None, :, 0] + (p[:, None, 1] - a[None, :, 1]) * (b[None, :, 0] - a[None, :, 0]) / np.where(
        b[None, :, 1] - a[None, :, 1] == 0, 1e-300, b[None, :, 1] - a[None, :, 1]
    )
    inside = (cond & (p[:, None, 0] < xint)).sum(axis=1) % 2 == 1
    ab = b - a
    t = np.clip(((p[:, None, :] - a[None]) * ab[None]).sum(-1) / np.maximum((ab * ab).sum(-1), 1e-300), 0, 1)
    d = np.linalg.norm(p[:, None, :] - (a[None] + t[..., None] * ab[None]), axis=-1).min(axis=1)
    d = np.where(inside, d, -1.0)
    k = int(np.argmax(d))
    if d[k] <= 0:
        return poly.mean(axis=0), 0.0
    return p[k], float(d[k])


def _shelves(sizes: list[tuple[float, float]], gap: float, max_width: float) -> tuple[list, float, float]:
    """Shelf packing of boxes: rows left to right, tallest first. Top-left corners, total width and height."""
    order = sorted(range(len(sizes)), key=lambda i: -sizes[i][1])
    pos: list[tuple[float, float]] = [(0.0, 0.0)] * len(sizes)
    x = y = row_h = width = 0.0
    for i in order:
        w, h = sizes[i]
        if x > 0 and x + w > max_width:
            x, y, row_h = 0.0, y + row_h + gap, 0.0
        pos[i] = (x, y)
        width = max(width, x + w)
        x += w + gap
        row_h = max(row_h, h)
    return pos, width, y + row_h


def _layout(pieces: list[Piece], gap: float) -> list[tuple[float, float]]:
    """Top-left corners of the pieces' boxes: the shelf packing whose sheet is closest to square."""
    sizes = [tuple(np.ptp(p.bounds, axis=0)) for p in pieces]
    widest = max(w for w, _ in sizes)
    full = sum(w for w, _ in sizes) + gap * len(sizes)
    best = None
    for limit in np.linspace(widest, max(full, widest), 40):
        pos, w, h = _shelves(sizes, gap, float(limit))
        score = max(w, h) ** 2 + 0.1 * w * h
        if best is None or score < best[0] - 1e-9:
            best = (score, pos)
    return best[1]


def _edge_frame(poly: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """Midpoint (by arc length), inward unit normal (y-up piece frame, CCW outline) and length of a polyline."""
    seg = np.diff(poly, axis=0)
    ln = np.linalg.norm(seg, axis=1)
    s = np.concatenate([[0.0], np.cumsum(ln)])
    half = 0.5 * s[-1]
    k = int(np.clip(np.searchsorted(s, half) - 1, 0, len(seg) - 1))
    t = (half - s[k]) / max(ln[k], 1e-300)
    mid = poly[k] + t * seg[k]
    d = seg[k] / max(ln[k], 1e-300)
    return mid, geo.perp(d), float(s[-1])


def _offset(poly: np.ndarray, dist: float) -> np.ndarray:
    """Shift a polyline (y-up frame) to its left (inside a CCW piece) by `dist`, point by point."""
    seg = np.diff(poly, axis=0)
    seg /= np.maximum(np.linalg.norm(seg, axis=1, keepdims=True), 1e-300)
    tang = np.concatenate([seg[:1], seg[:-1] + seg[1:], seg[-1:]])
    tang /= np.maximum(np.linalg.norm(tang, axis=1, keepdims=True), 1e-300)
    return poly + dist * geo.perp(tang)


def _trim(poly: np.ndarray, frac: float) -> np.ndarray:
    """The part of a polyline between arc-length fractions frac and 1 - frac."""
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(poly, axis=0), axis=1))])
    keep = np.linspace(frac * s[-1], (1 - frac) * s[-1], max(2, len(poly)))
    return np.stack([np.interp(keep, s, poly[:, 0]), np.interp(keep, s, poly[:, 1])], axis=-1)


def _at(poly: np.ndarray, frac: float) -> np.ndarray:
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(poly, axis=0), axis=1))])
    return np.array([np.interp(frac * s[-1], s, poly[:, 0]), np.interp(frac * s[-1], s, poly[:, 1])])


def pattern_sheet(pattern: Pattern, *, texture: TextureFill | None = None, annotate: bool = True) -> Sheet:
    """Lay out and annotate a pattern as a Sheet (cm, y down). `annotate=False` draws only the filled pieces."""
    pieces = pattern.pieces
    total = sum(float(np.prod(np.ptp(p.bounds, axis=0))) for p in pieces) or 1.0
    size = math.sqrt(total)
    gap = 0.06 * size
    pos = _layout(pieces, gap)
    unit = 0.028 * size  # base text size, cm: scales with the pattern so every sheet reads alike
    margin = 1.6 * unit
    top = 3.2 * unit if annotate else 0.0
    polys = {}
    bbox_all = np.zeros(2)
    for p, (x, y) in zip(pieces, pos, strict=True):
        lo, hi = p.bounds
        polys[p.name] = (lo, hi, x, y)
        bbox_all = np.maximum(bbox_all, [x + hi[0] - lo[0], y + hi[1] - lo[1]])

    def to_sheet(name: str, pts: np.ndarray) -> np.ndarray:
        lo, hi, x, y = polys[name]
        return np.stack([margin + x + pts[:, 0] - lo[0], top + margin + y + hi[1] - pts[:, 1]], axis=-1)

    sheet = Sheet(0.0, 0.0)
    items = sheet.items
    stroke_w = 0.09 * unit
    # Seams: colour per seam, and for each edge the seam it belongs to.
    seam_of: dict[tuple[str, int], tuple[int, bool]] = {}
    for s, seam in enumerate(pattern.seams):
        seam_of[(seam.a.piece, seam.a.edge)] = (s, False)
        seam_of[(seam.b.piece, seam.b.edge)] = (s, True)
    for p in pieces:
        lo, hi, x, y = polys[p.name]
        outline = to_sheet(p.name, p.polygon())
        items.append(
            Poly(
                outline,
                fill=PAPER if texture is None else None,
                texture=texture,
                texture_origin=(float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1])),
            )
        )
        sheet.texture_offsets[id(items[-1])] = (margin + x, top + margin + y)
        items.append(Poly(outline, stroke=INK, width=stroke_w))
    if annotate:
        for p in pieces:
            fs = unit * 0.62
            thin = float(np.ptp(p.bounds, axis=0).min())  # keep labels inside narrow pieces
            for e in range(p.n_edges):
                edge = p.sample_edge(e)
                mid, inward, length = _edge_frame(edge)
                efs = fs if length >= 1.2 * fs else 0.65 * fs
                sewn = seam_of.get((p.name, e))
                if sewn is not None:
                    s, is_b = sewn
                    colour = SEAM_COLOURS[s % len(SEAM_COLOURS)]
                    band = _offset(_trim(edge, 0.03 if length > 4 * unit else 0.0), 0.32 * unit)
                    items.append(Poly(to_sheet(p.name, band), stroke=colour, width=0.42 * unit, closed=False))
                    seam = pattern.seams[s]
                    # The dot marks the end that meets edge a's start.
                    near_start = not is_b or not seam.reversed
                    frac = 0.1 if near_start else 0.9
                    dot = _offset(edge, 0.32 * unit)
                    items.append(
                        Dot(
                            tuple(to_sheet(p.name, _at(dot, frac)[None])[0]),
                            0.34 * unit,
                            "#ffffff",
                            colour,
                            0.14 * unit,
                        )
                    )
                    if length >= 1.5 * unit:
                        badge = to_sheet(p.name, (mid + inward * 0.32 * unit)[None])[0]
                        items.append(Dot(tuple(badge), 0.5 * unit, colour))
                        items.append(Label((badge[0], badge[1]), str(s), 0.6 * unit, "#ffffff", bold=True))
                    lab = mid + inward * min(1.45 * unit, 0.8 * thin)
                else:
                    lab = mid + inward * min(0.75 * efs + 0.15 * unit, 0.5 * thin)
                items.append(Label(tuple(to_sheet(p.name, lab[None])[0]), str(e), efs, MUTED, halo=True))
            pole, room = _pole(p.polygon(tol_cm=0.2))
            chars = 0.62 * max(len(p.name), 4)  # text width / size
            across = min(1.15 * unit, 0.9 * room, 0.85 * 2.0 * room / chars)  # the roomiest spot's width
            bw, bh = np.ptp(p.bounds, axis=0)
            along = min(1.15 * unit, 0.45 * bw, 0.8 * bh / chars)  # turned upright along a tall narrow piece
            across_box = min(1.15 * unit, 0.85 * bw / chars)
            vertical = bh > 2.5 * bw and along > 1.3 * across_box
            name_size = max(along if vertical else across, 0.45 * unit)
            if vertical:  # centred on the piece's box, reading upwards
                yc = 0.5 * (p.bounds[0, 1] + p.bounds[1, 1]) + 0.17 * bh
                c = to_sheet(p.name, np.array([[0.5 * (p.bounds[0, 0] + p.bounds[1, 0]), yc]]))[0]
                items.append(
                    Label((c[0] - 0.1 * name_size, c[1]), p.name, name_size, INK, bold=True, halo=True, vertical=True)
                )
            else:
                c = to_sheet(p.name, pole[None])[0]
                items.append(Label((c[0], c[1] - 0.15 * name_size), p.name, name_size, INK, bold=True, halo=True))
                items.append(
                    Label((c[0], c[1] + 0.85 * name_size), f"{p.area:.0f} cm²", 0.7 * name_size, MUTED, halo=True)
                )
    width = 2 * margin + bbox_all[0]
    height = top + 2 * margin + bbox_all[1]
    if annotate:
        items.append(Label((margin, margin + 1.1 * unit), pattern.name, 1.5 * unit, INK, "start", bold=True))
        sub = f"{len(pieces)} pieces · {len(pattern.seams)} seams · cm"
        items.append(Label((margin, margin + 2.35 * unit), sub, 0.8 * unit, MUTED, "start"))
        # 10 cm scale bar at the top right of the pieces area
        x1 = width - margin
        x0 = x1 - 10.0
        yb = margin + 2.0 * unit
        items.append(Poly(np.array([[x0, yb], [x1, yb]]), stroke=INK, width=0.12 * unit, closed=False))
        for xx in (x0, x1):
            items.append(
                Poly(
                    np.array([[xx, yb - 0.3 * unit], [xx, yb + 0.3 * unit]]),
                    stroke=INK,
                    width=0.12 * unit,
                    closed=False,
                )
            )
        items.append(Label((0.5 * (x0 + x1), yb - 0.55 * unit), "10 cm", 0.7 * unit, INK))
        if pattern.seams:
            lx = width + 0.5 * margin
            fs = 0.62 * unit
            rows = []
            for s, seam in enumerate(pattern.seams):
                la, lb = pattern.edge_length(seam.a), pattern.edge_length(seam.b)
                arrow = "↔" if seam.reversed else "⇉"
                rows.append((s, f"{seam.a} {arrow} {seam.b}   {la:.1f} / {lb:.1f} cm"))
            items.append(Label((lx, top + margin + 0.2 * unit), "seams", 0.9 * unit, INK, "start", bold=True))
            line_h = 1.5 * fs
            for k, (s, text) in enumerate(rows):
                yy = top + margin + 1.4 * unit + k * line_h
                items.append(Dot((lx + 0.5 * fs, yy - 0.3 * fs), 0.55 * fs, SEAM_COLOURS[s % len(SEAM_COLOURS)]))
                items.append(Label((lx + 0.5 * fs, yy - 0.3 * fs), str(s), 0.62 * fs, "#ffffff", bold=True))
                items.append(Label((lx + 1.4 * fs, yy), text, fs, INK, "start"))
            longest = max(len(t) for _, t in rows)
            width = lx + 1.4 * fs + 0.56 * fs * longest + margin
            height = max(height, top + margin + 1.4 * unit + len(rows) * line_h + margin)
    sheet.width, sheet.height = float(width), float(height)
    return sheet


# ---- SVG ------------------------------------------------------------------------------------------------------------
def _png_bytes(img: np.ndarray) -> bytes:
    from PIL import Image

    buf = io.BytesIO()
    Image.fromarray(img).save(buf, format="PNG", optimize=True)
    return buf.getvalue()


def sheet_to_svg(sheet: Sheet) -> str:
    """The sheet as an SVG document in true size (1 user unit = 1 cm)."""
    w, h = sheet.width, sheet.height
    out = [
        '<?xml version="1.0" encoding="UTF-8"?>',
        f'<svg xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink" '
        f'width="{w:.3f}cm" height="{h:.3f}cm" viewBox="0 0 {w:.3f} {h:.3f}">',
        f'<rect x="0" y="0" width="{w:.3f}" height="{h:.3f}" fill="#ffffff"/>',
        '<g font-family="\'DejaVu Sans\', Helvetica, Arial, sans-serif" stroke-linejoin="round" '
        'stroke-linecap="round">',
    ]
    defs: list[str] = []
    tiles: dict[int, str] = {}
    for k, it in enumerate(sheet.items):
        if isinstance(it, Poly):
            d = " ".join(f"{x:.3f},{y:.3f}" for x, y in it.points)
            tag = "polygon" if it.closed else "polyline"
            fill = it.fill or "none"
            if it.texture is not None:
                tex = it.texture
                if id(tex) not in tiles:
                    tiles[id(tex)] = base64.b64encode(_png_bytes(tex.tile)).decode("ascii")
                ox, oy = sheet.texture_offsets[id(it)]
                minx, _, _, maxy = it.texture_origin
                tw, th = tex.tile_cm
                # Pattern point (x, y) sits at sheet (ox + x - minx, oy + maxy - y); the tile's top edge is at the
                # pattern's y = th (mod th), drawn upright: a pure translation.
                defs.append(
                    f'<pattern id="tex{k}" patternUnits="userSpaceOnUse" width="{tw:.4f}" height="{th:.4f}" '
                    f'patternTransform="translate({ox - minx:.4f},{oy + maxy - th:.4f})">'
                    f'<image width="{tw:.4f}" height="{th:.4f}" preserveAspectRatio="none" '
                    f'xlink:href="data:image/png;base64,{tiles[id(tex)]}"/></pattern>'
                )
                fill = f"url(#tex{k})"
            stroke = f' stroke="{it.stroke}" stroke-width="{it.width:.3f}"' if it.stroke else ""
            op = f' opacity="{it.opacity:.2f}"' if it.opacity < 1 else ""
            out.append(f'<{tag} points="{d}" fill="{fill}"{stroke}{op}/>')
        elif isinstance(it, Dot):
            stroke = f' stroke="{it.stroke}" stroke-width="{it.width:.3f}"' if it.stroke else ""
            out.append(
                f'<circle cx="{it.centre[0]:.3f}" cy="{it.centre[1]:.3f}" r="{it.radius:.3f}" '
                f'fill="{it.fill}"{stroke}/>'
            )
        elif isinstance(it, Label):
            anchor = "middle" if it.anchor == "middle" else "start"
            weight = ' font-weight="bold"' if it.bold else ""
            base = ' dominant-baseline="central"' if it.anchor == "middle" else ""
            rot = f' transform="rotate(-90 {it.pos[0]:.3f} {it.pos[1]:.3f})"' if it.vertical else ""
            attrs = (
                f'x="{it.pos[0]:.3f}" y="{it.pos[1]:.3f}" font-size="{it.size:.3f}" '
                f'text-anchor="{anchor}"{base}{weight}{rot}'
            )
            if it.halo:  # a white outline underneath (a separate element: not every renderer knows paint-order)
                out.append(
                    f'<text {attrs} fill="#ffffff" stroke="#ffffff" stroke-width="{0.22 * it.size:.3f}" '
                    f'stroke-opacity="0.85">{escape(it.text, quote=False)}</text>'
                )
            out.append(f'<text {attrs} fill="{it.colour}">{escape(it.text, quote=False)}</text>')
    out.append("</g></svg>")
    if defs:
        out.insert(3, "<defs>" + "".join(defs) + "</defs>")
    return "\n".join(out) + "\n"


_ASCII = str.maketrans({"²": "2", "↔": "-", "⇉": "=", "·": "-"})


# ---- PNG ------------------------------------------------------------------------------------------------------------
def sheet_to_png(sheet: Sheet, *, max_px: int = 2400, px_per_cm: float | None = None) -> np.ndarray:
    """Rasterise the sheet with Pillow: (H, W, 3) uint8, the longer side `max_px` unless px_per_cm is given.

    Shapes are drawn at twice the size and reduced (anti-aliasing); text uses Pillow's bundled font.
    """
    from PIL import Image, ImageDraw, ImageFont

    ppc = px_per_cm or max_px / max(sheet.width, sheet.height)
    ss = 2  # supersampling
    s = ppc * ss
    size = (max(1, round(sheet.width * s)), max(1, round(sheet.height * s)))
    img = Image.new("RGB", size, "#ffffff")
    draw = ImageDraw.Draw(img)
    fonts: dict[tuple[int, bool], tuple[object, bool]] = {}

    def font(px: int, bold: bool):
        """DejaVu Sans where the system has it (full Unicode), else Pillow's bundled font (ASCII labels)."""
        key = (px, bold)
        if key not in fonts:
            try:
                fonts[key] = (ImageFont.truetype("DejaVuSans-Bold.ttf" if bold else "DejaVuSans.ttf", max(4, px)), True)
            except OSError:
                fonts[key] = (ImageFont.load_default(size=max(4, px)), False)
        return fonts[key]

    for it in sheet.items:
        if isinstance(it, Poly):
            pts = [(float(x * s), float(y * s)) for x, y in it.points]
            if it.texture is not None:
                minx, miny, maxx, maxy = it.texture_origin
                ox, oy = sheet.texture_offsets[id(it)]
                # Drawn at the output resolution (it is anti-aliased itself), then enlarged to the supersampled
                # canvas: a quarter of the work.
                tex = it.texture.render((minx, miny), (maxx - minx, maxy - miny), ppc)
                target = (math.ceil((maxx - minx) * s), math.ceil((maxy - miny) * s))
                timg = Image.fromarray(tex).resize(target, Image.Resampling.BILINEAR)
                mask = Image.new("L", size, 0)
                ImageDraw.Draw(mask).polygon(pts, fill=255)
                canvas = Image.new("RGB", size)
                canvas.paste(timg, (round(ox * s), round(oy * s)))
                img.paste(canvas, (0, 0), mask)
            elif it.fill and it.closed:
                draw.polygon(pts, fill=it.fill)
            if it.stroke:
                width = max(1, round(it.width * s))
                line = pts + pts[:1] if it.closed else pts
                if it.opacity < 1:
                    layer = Image.new("RGBA", size, (0, 0, 0, 0))
                    ImageDraw.Draw(layer).line(line, fill=it.stroke, width=width, joint="curve")
                    alpha = layer.getchannel("A").point(lambda v, o=it.opacity: round(v * o))
                    layer.putalpha(alpha)
                    img.paste(layer, (0, 0), layer)
                    draw = ImageDraw.Draw(img)
                else:
                    draw.line(line, fill=it.stroke, width=width, joint="curve")
                    r = width / 2
                    for x, y in (line[0], line[-1]) if not it.closed else ():
                        draw.ellipse((x - r, y - r, x + r, y + r), fill=it.stroke)
        elif isinstance(it, Dot):
            x, y, r = it.centre[0] * s, it.centre[1] * s, it.radius * s
            draw.ellipse(
                (x - r, y - r, x + r, y + r),
                fill=it.fill,
                outline=it.stroke,
                width=max(1, round(it.width * s)) if it.stroke else 0,
            )
    # Text after the shapes (and after reduction, so the font hinting stays sharp).
    out = img.resize((size[0] // ss, size[1] // ss), Image.Resampling.LANCZOS)
    draw = ImageDraw.Draw(out)
    for it in sheet.items:
        if isinstance(it, Label):
            px = round(it.size * ppc)
            anchor = "mm" if it.anchor == "middle" else "ls"
            kw = {"stroke_width": max(1, round(0.12 * px)), "stroke_fill": "#ffffff"} if it.halo else {}
            face, unicode = font(px, it.bold)
            text = it.text if unicode else it.text.translate(_ASCII)
            if it.vertical:  # draw on a transparent patch, turn it, paste it centred on the position
                box = draw.textbbox((0, 0), text, font=face, anchor="lt", stroke_width=kw.get("stroke_width", 0))
                patch = Image.new("RGBA", (box[2] + 4, box[3] + 4), (0, 0, 0, 0))
                ImageDraw.Draw(patch).text((2, 2), text, fill=it.colour, font=face, anchor="lt", **kw)
                patch = patch.rotate(90, expand=True)
                at = (round(it.pos[0] * ppc - patch.width / 2), round(it.pos[1] * ppc - patch.height / 2))
                out.paste(patch, at, patch)
                continue
            draw.text((it.pos[0] * ppc, it.pos[1] * ppc), text, fill=it.colour, font=face, anchor=anchor, **kw)
    return np.asarray(out)
