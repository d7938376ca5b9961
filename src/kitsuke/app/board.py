"""The pattern board: the pattern's pieces laid flat on an upright board beside the body, in the same 3D scene, so
that the pattern and the body are both in view while drawing (the paper's two windows, side by side).

Board coordinates: the board is the plane z = `BoardLayout.z` (metres, facing +Z like the body), its pieces laid
left to right in rows at `scale` metres per pattern centimetre. A turned-over (flipped) piece is shown mirrored
left-right, as one sees its back. `to_board` and `to_piece` convert between a piece's own centimetres and the
board's metres.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Metres on the board per centimetre of pattern: a 150 cm kimono panel stands 0.75 m tall beside the body.
BOARD_SCALE = 0.005
#: Gap between pieces on the board, centimetres of pattern.
GAP_CM = 8.0


@dataclass(frozen=True)
class PiecePlace:
    """Where one piece lies on the board. origin : (2,) board metres (x, y) of the piece's lower-left bound
    corner. low : (2,) the piece's lower-left bound, cm. width_cm, height_cm : its size, cm. flipped : shown
    mirrored."""

    origin: np.ndarray
    low: np.ndarray
    width_cm: float
    height_cm: float
    flipped: bool


@dataclass(frozen=True)
class BoardLayout:
    """The pieces' places on the board (plane z = `z`, pieces from x = `x0` rightward)."""

    places: dict[str, PiecePlace]
    scale: float
    z: float

    @staticmethod
    def of(pattern, *, x0: float = 0.55, top: float = 1.85, z: float = 0.0, width_m: float = 1.6) -> BoardLayout:  # noqa: ANN001
        """Shelf-pack the pieces in pattern order, rows of at most `width_m` metres from (x0, top) down."""
        places: dict[str, PiecePlace] = {}
        s = BOARD_SCALE
        x, y, row_h = x0, top, 0.0
        for piece in pattern.pieces:
            low, high = piece.bounds
            w, h = (high - low) * s
            if x > x0 and x + w > x0 + width_m:
                x, y, row_h = x0, y - row_h - GAP_CM * s, 0.0
            size = high - low
            places[piece.name] = PiecePlace(
                np.array([x, y - h]), low.copy(), float(size[0]), float(size[1]), piece.flipped
            )
            x += w + GAP_CM * s
            row_h = max(row_h, h)
        return BoardLayout(places, s, z)

    def bounds(self) -> np.ndarray | None:
        """(2, 3) board metres: the lowest and highest corner of the box round every piece; None without pieces."""
        if not self.places:
            return None
        low = np.array([p.origin for p in self.places.values()])
        high = low + self.scale * np.array([[p.width_cm, p.height_cm] for p in self.places.values()])
        return np.c_[np.array([low.min(axis=0), high.max(axis=0)]), [self.z, self.z]]

    def to_board(self, piece: str, points_cm: np.ndarray) -> np.ndarray:
        """(n, 3) board metres of (n, 2) piece-local centimetres."""
        p = self.places[piece]
        local = np.asarray(points_cm, dtype=np.float64) - p.low
        if p.flipped:
            local[:, 0] = p.width_cm - local[:, 0]
        xy = p.origin + local * self.scale
        return np.c_[xy, np.full(len(xy), self.z)]

    def to_piece(self, piece: str, points_m: np.ndarray) -> np.ndarray:
        """(n, 2) piece-local centimetres of (n, 3) board points (their z is ignored)."""
        p = self.places[piece]
        local = (np.asarray(points_m, dtype=np.float64)[:, :2] - p.origin) / self.scale
        if p.flipped:
            local[:, 0] = p.width_cm - local[:, 0]
        return local + p.low

    def on_board(self, origin: np.ndarray, direction: np.ndarray) -> np.ndarray | None:
        """Where a ray (origin, direction: (3,) metres) meets the board's plane, or None (parallel, behind)."""
        d = float(direction[2])
        if abs(d) < 1e-9:
            return None
        t = (self.z - float(origin[2])) / d
        return None if t <= 0 else np.asarray(origin, dtype=np.float64) + t * np.asarray(direction, dtype=np.float64)
