"""The pattern editor of the app, as in the paper: "pieces are drawn as in an ordinary drawing editor; each has a
front and a back and can be turned over; edges can be sewn together". No user interface here: the app's view
calls these, and every change is one undoable step.

editor = PatternEditor(Pattern("skirt"))
front = editor.add_piece([[0, 0], [60, 0], [60, 55], [0, 55]])    # corners, cm; any winding
back = editor.duplicate(front)
editor.sew(EdgeRef(front, 1), EdgeRef(back, 3))                    # -> a warning when the lengths differ > 2 %
editor.curve_edge(front, 2, [30, 60])                              # edge 2's middle now passes through (30, 60)
editor.insert_point(front, 0, [30, 0]); editor.move_point(front, 1, [30, -3])
editor.issues()                                                    # what `kitsuke pattern validate` would say

Points and edges are those of the piece's own outline (cm, counter-clockwise): edge i runs from point i to i + 1.
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..pattern import Pattern
from ..pattern import _geometry as geo
from ..pattern._types import Curve, EdgeRef, Piece, Seam
from .history import History

#: An edge whose middle lies closer than this fraction of its length to its chord is made straight.
STRAIGHT_FRACTION = 0.01
#: Samples along an edge when finding the point of it nearest a click.
EDGE_SAMPLES = 400

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

    def edge_parameter(self, piece: str, edge: int, point_cm) -> float:  # noqa: ANN001
        """The curve parameter t in [0, 1] of the point of an edge nearest `point_cm` (piece cm)."""
        t = np.linspace(0.0, 1.0, EDGE_SAMPLES + 1)
        pts = self.pattern.piece(piece).edge_points(edge, t)
        return float(t[np.argmin(np.linalg.norm(pts - np.asarray(point_cm, dtype=np.float64), axis=1))])

    def handles(self, piece: str) -> tuple[np.ndarray, np.ndarray]:
        """Where a piece is edited: its points (n, 2) and its edges' middles (n, 2) (t = 0.5 on each), cm."""
        pc = self.pattern.piece(piece)
        return pc.outline.copy(), np.array([pc.edge_points(e, np.array([0.5]))[0] for e in range(pc.n_edges)])

    def move_point(self, piece: str, index: int, to_cm) -> str | None:  # noqa: ANN001
        """Move one point of a piece's outline (its two edges keep their curves, relative to their ends). Returns a
        warning when a seam on those edges now joins lengths that differ by more than the tolerance."""
        p = self.pattern.copy()
        k = p.piece_index(piece)
        src = p.pieces[k]
        out = src.outline.copy()
        out[index % src.n_edges] = np.asarray(to_cm, dtype=np.float64)
        p.pieces[k] = Piece(src.name, out, dict(src.curves), src.flipped, src.placement)
        self._apply(p)
        n = src.n_edges
        return self._seam_length_warning({EdgeRef(piece, (index - 1) % n), EdgeRef(piece, index % n)})

    def curve_edge(self, piece: str, edge: int, through_cm) -> None:  # noqa: ANN001
        """Bend an edge so that its middle (t = 0.5) passes through a point (cm): the handle drag of a drawing
        editor. A straight edge becomes a quadratic curve; a curved one keeps its kind; through the chord's middle,
        it becomes straight."""
        p = self.pattern.copy()
        k = p.piece_index(piece)
        src = p.pieces[k]
        edge %= src.n_edges
        a, b = src.edge_endpoints(edge)
        target = np.asarray(through_cm, dtype=np.float64)
        curves = dict(src.curves)
        if abs(float(geo.abs_to_rel(a, b, target)[0, 1])) < STRAIGHT_FRACTION:
            curves.pop(edge, None)
        else:
            old = curves.get(edge)
            shift = target - src.edge_points(edge, np.array([0.5]))[0]
            if old is None:  # B(1/2) = (a + 2c + b) / 4
                curves[edge] = Curve("quadratic", geo.abs_to_rel(a, b, 2.0 * target - 0.5 * (a + b)))
            elif old.type == "circle":  # the control point is the arc's middle itself
                curves[edge] = Curve("circle", [[0.5, float(geo.abs_to_rel(a, b, target)[0, 1])]])
            else:  # B(1/2) moves by 1/2 (quadratic) or 3/4 (cubic) of a shift of every control point
                ctrl = geo.rel_to_abs(a, b, old.control) + shift / (0.5 if old.type == "quadratic" else 0.75)
                curves[edge] = Curve(old.type, geo.abs_to_rel(a, b, ctrl))
        p.pieces[k] = Piece(src.name, src.outline.copy(), curves, src.flipped, src.placement)
        self._apply(p)

    def insert_point(self, piece: str, edge: int, at_cm) -> str | None:  # noqa: ANN001
        """Split an edge at the point of it nearest `at_cm` (a curve splits into two curves of the same shape).
        A seam on that edge is removed, and said in the returned warning (a seam joins whole edges)."""
        t = self.edge_parameter(piece, edge, at_cm)
        if not 0.02 < t < 0.98:
            raise InputError("that is a corner already: click nearer the middle of the edge to add a point")
        p = self.pattern.copy()
        k = p.piece_index(piece)
        src = p.pieces[k]
        edge %= src.n_edges
        c = src.curves.get(edge)
        mid, first, second = geo.split_curve(*src.edge_endpoints(edge), c and c.type, c and c.control, t)
        curves = {(e + (e > edge)): cv for e, cv in src.curves.items() if e != edge}
        for e, ctrl in ((edge, first), (edge + 1, second)):
            if ctrl is not None:
                curves[e] = Curve(c.type, ctrl)
        out = np.insert(src.outline, edge + 1, mid, axis=0)
        p.pieces[k] = Piece(src.name, out, curves, src.flipped, src.placement)
        dropped = self._renumber(p, piece, {edge}, lambda e: e + (e > edge))
        self._apply(p)
        return dropped

    def delete_point(self, piece: str, index: int) -> str | None:
        """Remove one point of a piece's outline: its two edges become one straight edge. Seams on either are
        removed, and said in the returned warning. InputError: a piece keeps at least 3 points."""
        p = self.pattern.copy()
        k = p.piece_index(piece)
        src = p.pieces[k]
        n = src.n_edges
        if n <= 3:
            raise InputError(f"piece {piece!r} has 3 points, the fewest a piece can have")
        i = index % n
        merged = {(i - 1) % n, i}
        curves = {(e - (e > i)): cv for e, cv in src.curves.items() if e not in merged}
        p.pieces[k] = Piece(src.name, np.delete(src.outline, i, axis=0), curves, src.flipped, src.placement)
        dropped = self._renumber(p, piece, merged, lambda e: e - (e > i))
        self._apply(p)
        return dropped

    @staticmethod
    def _renumber(p: Pattern, piece: str, gone: set[int], new_index) -> str | None:  # noqa: ANN001
        """Seams after an outline edit: those on edges in `gone` removed, the others' edges renumbered (in place).
        Returns the warning that names the removed seams, or None."""
        kept, removed = [], []
        for s in p.seams:
            if any(r.piece == piece and r.edge in gone for r in (s.a, s.b)):
                removed.append(f"{s.a}–{s.b}")
                continue
            a, b = (EdgeRef(r.piece, new_index(r.edge)) if r.piece == piece else r for r in (s.a, s.b))
            kept.append(Seam(a, b, s.reversed))
        p.seams = kept
        return f"seam {', '.join(removed)} removed: its edge changed (sew it again)" if removed else None

    def _seam_length_warning(self, edges: set[EdgeRef]) -> str | None:
        for s in self.pattern.seams:
            if s.a in edges or s.b in edges:
                la, lb = self.pattern.edge_length(s.a), self.pattern.edge_length(s.b)
                diff = abs(la - lb) / max(la, lb)
                if diff > SEAM_LENGTH_TOLERANCE:
                    return f"edges {s.a} and {s.b} differ in length by {100 * diff:.0f} % ({la:.1f} and {lb:.1f} cm)"
        return None

    def reverse_seam(self, edge: EdgeRef) -> None:
        """Turn the seam on an edge round: a's start then meets b's start instead of b's end (a twisted seam
        undone, or made). InputError when the edge is not sewn."""
        p = self.pattern.copy()
        for k, s in enumerate(p.seams):
            if edge in (s.a, s.b):
                p.seams[k] = Seam(s.a, s.b, not s.reversed)
                self._apply(p)
                return
        raise InputError(f"edge {edge} is not sewn")

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
        p = self.pattern.copy()
        p.seams.append(Seam(a, b, True))
        self._apply(p)
        return self._seam_length_warning({a})

    def unsew(self, edge: EdgeRef) -> None:
        """Remove the seam on an edge. InputError when the edge is not sewn."""
        kept = [s for s in self.pattern.seams if edge not in (s.a, s.b)]
        if len(kept) == len(self.pattern.seams):
            raise InputError(f"edge {edge} is not sewn")
        p = self.pattern.copy()
        p.seams = kept
        self._apply(p)

    def issues(self) -> list:
        """What `kitsuke pattern validate` says of the pattern now (`Issue`s), errors first."""
        from ..pattern import validate

        return sorted(validate(self.pattern), key=lambda i: i.severity != "error")
