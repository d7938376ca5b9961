"""SVG import: FreeSewing pieces, true size, areas against svgelements' own geometry, generic SVGs, bad files."""

from __future__ import annotations

import numpy as np
import pytest
import svgelements as se

from kitsuke.errors import InputError
from kitsuke.pattern import load_pattern

from .conftest import TEAGAN

CM_PER_PX = 2.54 / 96


def reference_areas() -> dict[str, float]:
    """Areas (cm^2) of the FreeSewing 'fabric' paths from svgelements' densely sampled outline (shoelace)."""
    svg = se.SVG.parse(str(TEAGAN))
    out = {}
    for e in svg.elements():
        if isinstance(e, se.Path) and e.values.get("class") == "fabric":
            pts = np.array(e.npoint(np.linspace(0, 1, 100_001)))
            x, y = pts[:, 0], pts[:, 1]
            out[e.id] = 0.5 * abs(x @ np.roll(y, -1) - np.roll(x, -1) @ y) * CM_PER_PX**2
    return out


def test_freesewing_tshirt_pieces_and_areas(teagan):
    assert [p.name for p in teagan.pieces] == ["front", "back", "sleeve"]
    assert teagan.seams == []
    ref = reference_areas()  # fs-1 front, fs-8 back, fs-17 sleeve, in document order
    for piece, (_, area) in zip(teagan.pieces, sorted(ref.items(), key=lambda kv: int(kv[0][3:])), strict=True):
        assert piece.area == pytest.approx(area, rel=0.01)
        assert piece.area == pytest.approx(area, rel=1e-4)  # much closer than the 1 % asked for
        assert piece.signed_area > 0  # counter-clockwise with y up
        np.testing.assert_allclose(piece.bounds[0], [0.0, 0.0], atol=1e-9)
    # True size: the front's hem is 273.76 mm wide in the file.
    assert teagan.piece("front").edge_length(0) == pytest.approx(27.376, abs=1e-3)
    # Curves are kept as Béziers, not sampled.
    assert {c.type for p in teagan.pieces for c in p.curves.values()} == {"cubic"}
    # y flipped: the sleeve cap (the highest part of the drawing) is at the top.
    sleeve = teagan.piece("sleeve")
    assert sleeve.polygon()[:, 1].argmax() in range(len(sleeve.polygon()))
    top = sleeve.polygon()[sleeve.polygon()[:, 1].argmax()]
    assert top[1] == pytest.approx(sleeve.bounds[1, 1]) and 0.3 < top[0] / sleeve.bounds[1, 0] < 0.7


GENERIC = """<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="50mm" viewBox="0 0 100 50">
  <defs><path id="marker" d="M 0 0 L 5 0 L 5 5 z"/></defs>
  <rect id="panel" x="10" y="10" width="20" height="30"/>
  <g transform="translate(40 0)">
    <path d="M 0 40 Q 10 0 20 40 Z"/>
    <path d="M 30 40 A 10 10 0 0 1 50 40 Z"/>
  </g>
  <path d="M 0 0 L 10 10"/>
</svg>"""


def test_generic_svg_closed_shapes(tmp_path):
    path = tmp_path / "shapes.svg"
    path.write_text(GENERIC)
    pattern = load_pattern(path)
    assert [p.name for p in pattern.pieces] == ["panel", "piece_2", "piece_3"]  # open path and <defs> skipped
    panel, arch, dome = pattern.pieces
    assert panel.area == pytest.approx(2.0 * 3.0, rel=1e-5)  # 20 x 30 mm
    assert arch.curves[next(iter(arch.curves))].type == "quadratic"
    assert arch.area == pytest.approx(2 / 3 * 2.0 * 2.0, rel=1e-5)  # parabola under a 20 mm chord, 20 mm high
    assert dome.area == pytest.approx(np.pi * 1.0**2 / 2, rel=1e-3)  # half disc of radius 10 mm, arc as cubics
    assert all(p.signed_area > 0 for p in pattern.pieces)


@pytest.mark.parametrize(
    ("content", "expected"),
    [
        ("<svg xmlns='http://www.w3.org/2000/svg'><path d='M 0 0 L 1 1'/></svg>", "no closed shapes"),
        ("this is not xml <svg", "not a readable SVG"),
        ("<svg xmlns='http://www.w3.org/2000/svg'><path d='M 0 0 L 10 10 L 10 0 L 0 10 Z'/></svg>", "crosses itself"),
    ],
)
def test_bad_svg_files(tmp_path, content, expected):
    path = tmp_path / "bad.svg"
    path.write_text(content)
    with pytest.raises(InputError) as err:
        load_pattern(path)
    assert err.value.path == str(path) and expected in err.value.message
