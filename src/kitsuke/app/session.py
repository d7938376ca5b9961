"""One user's dressing in the app: a body, a pattern, the stroke pairs drawn so far, and the dressed garment.

No user interface here: the app's views call these methods and draw what they hold. Pattern strokes are kept in
the coordinates of the pattern's file (as stroke files and `wrap` take them); the board shows them on the pieces.

session = DressingSession(default_body(), default_kimono())
session.draw_pattern_stroke("migoro_right", points_cm)   # a stroke on a piece (file coordinates, cm)
pair = session.draw_body_stroke(points_m)                # its partner on the body: pair 1
session.undo(); session.redo()
session.strokes()                                        # Strokes, for wrap or a file
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..dressing import BodyStroke, PatternStroke, StrokePair, Strokes, in_piece_frame
from ..errors import InputError
from ..geometry.surface import Surface
from .history import History

#: Colours of stroke pairs, by number (the paper numbers and colours each pair); sRGB 0-255.
PAIR_COLORS = (
    (230, 25, 75), (60, 180, 75), (0, 130, 200), (245, 130, 48), (145, 30, 180),
    (70, 200, 200), (240, 50, 230), (150, 110, 40), (0, 128, 128), (128, 0, 0),
)  # fmt: skip


def pair_color(pair_id: int) -> tuple[int, int, int]:
    return PAIR_COLORS[(pair_id - 1) % len(PAIR_COLORS)]


@dataclass
class _State:
    pairs: list[StrokePair] = field(default_factory=list)
    waiting: tuple[PatternStroke, ...] = ()  # the last pattern strokes drawn without a partner (at most 2)
    garment_pairs: list[StrokePair] = field(default_factory=list)  # re-wrap strokes, drawn on the garment
    redraw: int | None = None  # the number the next pair drawn takes (a pair being redrawn)


class DressingSession:
    """The state of one dressing: body and pattern (fixed), stroke pairs (drawn, with undo and redo), and the
    garment last dressed. body : a `kitsuke.body.Body`; pattern : a `kitsuke.pattern.Pattern`."""

    def __init__(self, body, pattern, strokes: Strokes | None = None) -> None:  # noqa: ANN001
        self.body = body
        self.pattern = pattern
        self.surface = Surface(body.mesh)
        self._history = History(_State())
        self.garment = None
        if strokes is not None:
            self.load_strokes(strokes)

    # -- the drawing ----------------------------------------------------------------------------------------
    @property
    def _state(self) -> _State:
        return self._history.now

    @property
    def pairs(self) -> list[StrokePair]:
        return list(self._state.pairs)

    @property
    def pending(self) -> PatternStroke | None:
        """The pattern stroke waiting for its body stroke (the next stroke drawn on the body)."""
        return self._state.waiting[-1] if self._state.waiting else None

    @property
    def waiting(self) -> tuple[PatternStroke, ...]:
        """The last two pattern strokes drawn without a partner: a laser stroke pairs with both."""
        return self._state.waiting

    def next_id(self) -> int:
        """The number of the next pair drawn: the one being redrawn, or one past the highest."""
        if self._state.redraw is not None:
            return self._state.redraw
        return max((p.id for p in self._state.pairs), default=0) + 1

    def _change(
        self,
        pairs: list[StrokePair],
        waiting: tuple[PatternStroke, ...],
        garment_pairs: list | None = None,
        redraw: int | None = None,
    ) -> None:
        """A new state (undoable); pairs kept in number order. A number being redrawn stays so until a pair
        takes it (or `redraw` names another)."""
        kept = self._state.garment_pairs if garment_pairs is None else garment_pairs
        if redraw is None and self._state.redraw not in {p.id for p in pairs}:
            redraw = self._state.redraw
        self._history.push(_State(sorted(pairs, key=lambda p: p.id), waiting, list(kept), redraw))

    def draw_pattern_stroke(self, piece: str, points_cm: np.ndarray) -> PatternStroke:
        """A stroke on a piece, in the pattern file's coordinates (cm); it waits for its body stroke (a body
        stroke pairs with the last one drawn, a laser stroke with the last two). InputError: unknown piece, fewer
        than 2 points, a zero-length stroke."""
        if piece not in self.pattern.piece_names:
            raise InputError(f"no piece named {piece!r} in the pattern")
        stroke = PatternStroke(piece, np.asarray(points_cm, dtype=np.float64))
        self._change(list(self._state.pairs), (*self._state.waiting[-1:], stroke))
        return stroke

    def draw_body_stroke(self, points_m: np.ndarray) -> StrokePair:
        """The body stroke of the waiting pattern stroke: (n, 3) points on (or near) the body, metres, put on its
        surface. Returns the new pair. InputError when no pattern stroke waits."""
        pending = self.pending
        if pending is None:
            raise InputError("draw the stroke on the pattern first, then its partner on the body")
        body = BodyStroke(points=np.asarray(points_m, dtype=np.float64))
        body.surface = self.surface.closest(body.points)
        pair = StrokePair(self.next_id(), pending, body)
        self._change([*self._state.pairs, pair], ())
        return pair

    def draw_laser_stroke(self, rays: np.ndarray) -> tuple[StrokePair, StrokePair]:
        """One stroke across the body for the last two pattern strokes (the paper's laser): (n, 6) rays, origin
        then direction, metres. Where they first enter the body pairs with the first of the two (a front piece),
        where they last leave it with the second (a back piece). InputError: fewer than two pattern strokes
        waiting, or rays that miss the body."""
        if len(self._state.waiting) < 2:
            raise InputError("a laser stroke needs two pattern strokes first: the front piece's, then the back's")
        rays = np.asarray(rays, dtype=np.float64)
        strokes = []
        for hit in ("first", "last"):
            b = BodyStroke(rays=rays, hit=hit)
            sp = self.surface.cast(rays[:, :3], rays[:, 3:], hit=hit)
            if not sp.hit.all():
                raise InputError("the laser stroke must cross the body from start to end")
            b.surface = sp
            strokes.append(b)
        front, back = self._state.waiting
        n = self.next_id()
        after = max([n, *(p.id for p in self._state.pairs)]) + 1
        pairs = (StrokePair(n, front, strokes[0]), StrokePair(after, back, strokes[1]))
        self._change([*self._state.pairs, *pairs], ())
        return pairs

    @property
    def garment_pairs(self) -> list[StrokePair]:
        """Re-wrap stroke pairs: pattern strokes (in their piece's own coordinates) and strokes drawn on the
        dressed garment."""
        return list(self._state.garment_pairs)

    def draw_garment_stroke(self, points_m: np.ndarray, garment_surface: Surface) -> StrokePair:
        """A re-wrap stroke: the waiting pattern stroke goes where (n, 3) points drawn on the dressed garment
        (`garment_surface`, the garment as it is now) say. InputError when no pattern stroke waits."""
        pending = self.pending
        if pending is None:
            raise InputError("draw the stroke on the pattern first, then where it should go on the garment")
        body = BodyStroke(points=np.asarray(points_m, dtype=np.float64))
        body.surface = garment_surface.closest(body.points)
        piece_points = self.pattern.file_to_piece(pending.piece, pending.points)  # a re-wrap names piece coordinates
        ids = [p.id for p in self._state.garment_pairs]
        pair = StrokePair(max(ids, default=0) + 1, PatternStroke(pending.piece, piece_points), body)
        self._change(list(self._state.pairs), (), [*self._state.garment_pairs, pair])
        return pair

    def garment_strokes(self) -> Strokes:
        """The re-wrap pairs as Strokes with target "garment" (what `kitsuke.dressing.rewrap.rewrap` takes)."""
        return Strokes(list(self._state.garment_pairs), "garment", {"drawn_in": "kitsuke app"})

    def garment_changed(self) -> None:
        """A re-wrap or a new wrap: the re-wrap strokes were for the garment before it."""
        self._change(list(self._state.pairs), self._state.waiting, [])

    def delete(self, pair_id: int, *, redraw: bool = False) -> None:
        """Remove a pair; with `redraw`, the next pair drawn takes its number (and colour). InputError: no such
        pair."""
        pairs = [p for p in self._state.pairs if p.id != pair_id]
        if len(pairs) == len(self._state.pairs):
            raise InputError(f"no stroke pair {pair_id}")
        self._change(pairs, self._state.waiting, redraw=pair_id if redraw else None)

    def clear(self) -> None:
        self._history.push(_State([], (), list(self._state.garment_pairs)))

    def undo(self) -> bool:
        return self._history.undo()

    def redo(self) -> bool:
        return self._history.redo()

    # -- strokes in and out ---------------------------------------------------------------------------------
    def strokes(self) -> Strokes:
        """The pairs drawn, as Strokes (pattern points in the file's coordinates)."""
        return Strokes(list(self._state.pairs), "body", {"drawn_in": "kitsuke app"})

    def wrap_strokes(self) -> Strokes:
        """The pairs as `kitsuke.dressing.wrap` takes strokes already on the body: pattern points in the pieces'
        own coordinates (a GarmentCode file mirrors some pieces; `strokes()` keeps the file's)."""
        return in_piece_frame(self.strokes(), self.pattern)

    def load_strokes(self, strokes: Strokes) -> None:
        """Replace the pairs by those of a strokes file (checked against the pattern; body strokes put on the
        body)."""
        from ..dressing import check_strokes

        if strokes.target != "body":
            raise InputError("these strokes re-wrap a garment; load strokes drawn on the body", strokes.source)
        check_strokes(strokes, self.pattern)
        pairs = []
        for p in strokes.pairs:
            body = p.body
            if not body.resolved:
                body = BodyStroke(points=body.points, rays=body.rays, hit=body.hit)
                body.surface = (
                    self.surface.closest(body.points)
                    if body.points is not None
                    else self.surface.cast(body.rays[:, :3], body.rays[:, 3:], hit=body.hit)
                )
            pairs.append(StrokePair(p.id, p.pattern, body))
        self._change(pairs, ())

    def suggest(self) -> int:
        """Replace the pairs by `kitsuke.dressing.suggest_strokes` (the pattern's placement carried to the body);
        returns how many pairs."""
        from ..dressing import suggest_strokes

        self.load_strokes(suggest_strokes(self.body, self.pattern, surface=self.surface))
        return len(self._state.pairs)

    def pattern_points_on_piece(self, pair: StrokePair) -> np.ndarray:
        """(n, 2) the pair's pattern stroke in its piece's own coordinates, cm (what the board shows)."""
        one = Strokes([pair], "body")
        return in_piece_frame(one, self.pattern).pairs[0].pattern.points
