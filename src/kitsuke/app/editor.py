"""The pattern editor of the app, as in the paper: "pieces are drawn as in an ordinary drawing editor; each has a
front and a back and can be turned over; edges can be sewn together". No user interface here: the app's view
calls these, and every change is one undoable step.

editor = PatternEditor(Pattern("skirt"))
front = editor.add_piece([[0, 0], [60, 0], [60, 55], [0, 55]])    # corners, cm; any winding
back = editor.duplicate(front)
editor.sew(EdgeRef(front, 1), EdgeRef(back, 3))                    # -> a warning when the lengths differ > 2 %
editor.issues()                                                    # what `kitsuke pattern validate` would say
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..pattern import Pattern
from ..pattern._types import EdgeRef, Piece, Seam
from .history import History

#: Two sewn edges whose lengths differ by more than this fraction get a warning (they would pucker or stretch).
SEAM_LENGTH_TOLERANCE = 0.02


class PatternEditor:
    """A pattern being edited, with undo and redo. `pattern` is the pattern now (a new object after each change)."""

    def __init__(self, pattern: Pattern) -> None:
        self._history = History(pattern)

    @property
    def pattern(self) -> Pattern:
        return self._history.now

    def _apply(self, pattern: Pattern) -> None:
        self._history.push(pattern)

    def undo(self) -> bool:
        return self._history.undo()

    def redo(self) -> bool:
        return self._history.redo()

    def new(self, name: str = "garment") -> None:
        """Start from nothing: an empty pattern (undoable)."""
        self._apply(Pattern(name))

    def _name(self, stem: str) -> str:
        names = set(self.pattern.piece_names)
        k = 1
        while f"{stem}{k}" in names:
            k += 1
        return f"{stem}{k}"

    def add_piece(self, corners_cm, name: str | None = None) -> str:  # noqa: ANN001 - (n, 2) array-like
        """A new straight-edged piece from its corners (cm, either winding; made counter-clockwise). InputError:
        fewer than 3 corners, or a piece with no area."""
        pts = np.asarray(corners_cm, dtype=np.float64)
        if pts.ndim != 2 or pts.shape[1] != 2 or len(pts) < 3:
            raise InputError("a piece needs at least 3 corners")
        area = 0.5 * float(np.sum(pts[:, 0] * np.roll(pts[:, 1], -1) - np.roll(pts[:, 0], -1) * pts[:, 1]))
        if abs(area) < 1.0:
            raise InputError("those corners enclose no area (under 1 cm²): click the corners around the piece")
        if area < 0:
            pts = pts[::-1]
        pts = pts - pts.min(axis=0)  # piece-local: its lower-left bound at the origin
        name = name or self._name("piece")
        p = self.pattern.copy()
        p.pieces.append(Piece(name, pts))
        self._apply(p)
        return name

    def duplicate(self, piece: str) -> str:
        """A copy of a piece (outline, curves, turned over or not), under a new name; its seams are not copied."""
        src = self.pattern.piece(piece)
        p = self.pattern.copy()
        twin = src.copy()
        twin.name = self._name(f"{piece}_copy")
        twin.placement = None
        p.pieces.append(twin)
        self._apply(p)
        return twin.name

    def mirror(self, piece: str) -> None:
        """Mirror a piece left-right in place (a left sleeve from a right one); its seams keep their edges."""
        p = self.pattern.copy()
        k = p.piece_index(piece)
        src = p.pieces[k]
        n = src.n_edges
        # mirrored, the outline runs clockwise; its corners taken backwards (rolled by one) make it counter-
        # clockwise again, and edge i (corner i to i+1) becomes edge n-1-i, traversed the other way
        out = np.roll((src.outline * [-1.0, 1.0])[::-1], 1, axis=0)
        out = out - out.min(axis=0)
        curves = {n - 1 - e: c.mirrored().reversed() for e, c in src.curves.items()}
        p.pieces[k] = Piece(src.name, out, curves, src.flipped, None)

        def moved(r: EdgeRef) -> EdgeRef:
            return EdgeRef(r.piece, n - 1 - r.edge) if r.piece == piece else r

        # an edge that now runs the other way meets its partner the other way round
        p.seams = [Seam(moved(s.a), moved(s.b), s.reversed ^ ((s.a.piece == piece) != (s.b.piece == piece)))
                   for s in p.seams]  # fmt: skip
        self._apply(p)

    def flip(self, piece: str) -> None:
        """Turn a piece over: its back becomes its outside."""
        p = self.pattern.copy()
        k = p.piece_index(piece)
        p.pieces[k].flipped = not p.pieces[k].flipped
        self._apply(p)

    def delete_piece(self, piece: str) -> None:
        """Remove a piece and every seam on it."""
        p = self.pattern.copy()
        p.pieces.pop(p.piece_index(piece))
        p.seams = [s for s in p.seams if piece not in (s.a.piece, s.b.piece)]
        self._apply(p)

    def nearest_edge(self, piece: str, point_cm) -> int:  # noqa: ANN001
        """The edge of `piece` nearest a point (cm, the piece's own coordinates)."""
        pc = self.pattern.piece(piece)
        q = np.asarray(point_cm, dtype=np.float64)
        best, best_d = 0, np.inf
        for e in range(pc.n_edges):
            pts = pc.sample_edge(e)
            a, b = pts[:-1], pts[1:]
            ab = b - a
            t = np.clip(np.einsum("ij,ij->i", q - a, ab) / np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-12), 0, 1)
            d = float(np.min(np.linalg.norm(a + t[:, None] * ab - q, axis=1)))
            if d < best_d:
                best, best_d = e, d
        return best

    def sew(self, a: EdgeRef, b: EdgeRef) -> str | None:
        """Sew two edges (a's start to b's end, as two pieces facing out meet). Returns a warning when their
        lengths differ by more than `SEAM_LENGTH_TOLERANCE`, else None. InputError: an edge sewn to itself, or
        one already in a seam."""
        if a == b:
            raise InputError("an edge cannot be sewn to itself")
        for s in self.pattern.seams:
            for r in (a, b):
                if r in (s.a, s.b):
                    raise InputError(f"edge {r} is already sewn (unsew it first)")
        la, lb = self.pattern.edge_length(a), self.pattern.edge_length(b)
        p = self.pattern.copy()
        p.seams.append(Seam(a, b, True))
        self._apply(p)
        diff = abs(la - lb) / max(la, lb)
        if diff > SEAM_LENGTH_TOLERANCE:
            return f"edges {a} and {b} differ in length by {100 * diff:.0f} % ({la:.1f} and {lb:.1f} cm)"
        return None

    def unsew(self, edge: EdgeRef) -> None:
        """Remove the seam on an edge. InputError when the edge is not sewn."""
        kept = [s for s in self.pattern.seams if edge not in (s.a, s.b)]
        if len(kept) == len(self.pattern.seams):
            raise InputError(f"edge {edge} is not sewn")
        p = self.pattern.copy()
        p.seams = kept
        self._apply(p)

    def issues(self) -> list[str]:
        """What `kitsuke pattern validate` says of the pattern now: errors first, one line each."""
        from ..pattern import validate

        found = sorted(validate(self.pattern), key=lambda i: i.severity != "error")
        return [f"{i.severity}: {i.message}" for i in found]
