"""The pattern editor's part of a tab: its tools in the panel, what it draws on the board (seams with their
direction, the pattern's errors on their pieces, the points and edge middles to drag) and what clicks and drags on
the board do while editing. Thin: every change is a `PatternEditor` call; the tab then rebuilds its scene.
"""

from __future__ import annotations

import tempfile
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..errors import InputError
from ..pattern._types import EdgeRef
from .editor import PatternEditor

if TYPE_CHECKING:
    from .view import ClientView

#: One colour for every seam: the stroke pairs own the bright ones.
SEAM_COLOR = (120, 120, 190)
#: Handle radius, metres on the board (2.4 cm of pattern).
HANDLE_RADIUS_M = 0.012
#: A handle dragged less than this (board metres) stays where it was: a click that shook.
CLICK_SLOP_M = 0.004


class EditorTools:
    """The pattern editor of one tab. `editor` holds the pattern being edited and its undo history."""

    def __init__(self, view: ClientView, editor: PatternEditor) -> None:
        self.view = view
        self.editor = editor
        self.corners: list[np.ndarray] = []  # a piece being drawn, corner by corner (board metres)
        self.sewing: list[EdgeRef] = []  # the first edge picked for a seam
        self.selected_point: tuple[str, int] | None = None  # (piece, point index) in point mode
        self.seam_handle = None

    # -- panel ------------------------------------------------------------------------------------------------
    def build_panel(self, gui) -> None:  # noqa: ANN001 - a viser GuiApi
        v = self.view
        gui.add_button("New empty pattern").on_click(lambda _: self.apply(self.editor.new))
        self.piece_mode = gui.add_checkbox("Draw a piece: click its corners", False)
        gui.add_button("Close the piece").on_click(lambda _: self._close_piece())
        self.sew_mode = gui.add_checkbox("Sew: click two edges", False)
        self.point_mode = gui.add_checkbox(
            "Edit points", False,
            hint="drag a red point to move it, a blue one to bend its edge; click an edge to add a point there, "
            "click a point to select it for Delete point",
        )  # fmt: skip
        self.point_mode.on_update(lambda _: v.rebuild_scene())
        gui.add_button("Delete point").on_click(lambda _: self._delete_point())
        self.seam_choice = gui.add_dropdown("Seam", self._seam_names())
        gui.add_button("Reverse seam").on_click(lambda _: self._seam_action(self.editor.reverse_seam))
        gui.add_button("Unsew").on_click(lambda _: self._seam_action(self.editor.unsew))
        for label, action in (
            ("Duplicate piece", self.editor.duplicate),
            ("Mirror piece", self.editor.mirror),
            ("Delete piece", self.editor.delete_piece),
        ):
            gui.add_button(label).on_click(lambda _, act=action: self.apply(lambda: act(v.flip_choice.value)))
        gui.add_button("Undo edit").on_click(lambda _: self.apply(self.editor.undo))
        gui.add_button("Redo edit").on_click(lambda _: self.apply(self.editor.redo))
        gui.add_button("Save pattern (JSON)").on_click(lambda _: self._download_pattern())
        self.issues_md = gui.add_markdown("")

    def refresh_panel(self) -> None:
        """The issues and the seam list, for the pattern now."""
        found = [f"{i.severity}: {i.message}" for i in self.editor.issues()]
        self.issues_md.content = "\n\n".join(found[:6]) if found else "No problems found in the pattern."
        self.seam_choice.options = self._seam_names()

    def apply(self, action) -> None:  # noqa: ANN001 - an editor call
        """Do one edit; say its warning (a length mismatch, a seam it removed) or why it was not done."""
        try:
            warning = action()
        except InputError as e:
            self.view.notify("Not done", e.message, "red")
            return
        if isinstance(warning, str):
            self.view.notify("Done, but", warning, "yellow")
        self.view.pattern_edited(self.editor.pattern)

    # -- what the board shows ---------------------------------------------------------------------------------
    def draw(self) -> None:
        self._draw_seams()
        self._draw_problems()
        self._draw_handles()

    def show_seams(self, on: bool) -> None:
        if self.seam_handle is not None:
            self.seam_handle.visible = on

    def _draw_seams(self) -> None:
        """Each seam: its two edges drawn thick and numbered alike, and one thin line from near a's start to the
        point of b it meets there (the seam's direction: a twisted seam's line runs to the far end of b)."""
        board, scene, pattern = self.view.board, self.view.client.scene, self.view.session.pattern
        edges, links, labels = [], [], []
        for k, seam in enumerate(pattern.seams):
            for ref in (seam.a, seam.b):
                piece = pattern.piece(ref.piece)
                pts = board.to_board(ref.piece, piece.sample_edge(ref.edge))
                edges += list(np.stack([pts[:-1], pts[1:]], axis=1))
                mid = board.to_board(ref.piece, piece.edge_points(ref.edge, np.array([0.5])))[0]
                labels.append((f"{k}_{ref.piece}_{ref.edge}", str(k), mid + [0, 0, 0.005]))
            t = np.array([0.2])
            a = board.to_board(seam.a.piece, pattern.piece(seam.a.piece).edge_points(seam.a.edge, t))
            b = board.to_board(seam.b.piece, pattern.piece(seam.b.piece).edge_points(
                seam.b.edge, 1 - t if seam.reversed else t))  # fmt: skip
            links.append([a[0], b[0]])
        self.seam_handle = None
        if not edges:
            return
        self.seam_handle = scene.add_line_segments(
            "/board/seams", np.array(edges) + [0, 0, 0.004], SEAM_COLOR, thickness=3.0, thickness_units="screen"
        )
        scene.add_line_segments(
            "/board/seams/links", np.array(links) + [0, 0, 0.004], (120, 120, 140), thickness=1.0,
            thickness_units="screen",
        )  # fmt: skip
        for name, text, at in labels:  # children of the seams' node: Show seams hides them too
            scene.add_label(f"/board/seams/{name}", text, position=tuple(at))

    def _draw_problems(self) -> None:
        """The pattern's errors where they are: the edges at fault drawn red on their piece, with the message."""
        board, scene = self.view.board, self.view.client.scene
        for k, issue in enumerate(i for i in self.editor.issues() if i.severity == "error" and i.piece):
            if issue.piece not in board.places:
                continue
            piece = self.view.session.pattern.piece(issue.piece)
            for e in issue.edges or tuple(range(piece.n_edges)):
                pts = board.to_board(issue.piece, piece.sample_edge(e)) + [0, 0, 0.005]
                scene.add_line_segments(
                    f"/board/problems/{k}/{e}", np.stack([pts[:-1], pts[1:]], axis=1), (220, 30, 30),
                    thickness=5.0, thickness_units="screen",
                )  # fmt: skip
            low, high = piece.bounds
            at = board.to_board(issue.piece, np.array([(low + high) / 2]))[0] + [0, 0, 0.01]
            scene.add_label(f"/board/problems/{k}/label", issue.message, position=tuple(at))

    def _draw_handles(self) -> None:
        """In point mode: each piece's points (drag to move, click to select) and its edges' middles (drag to
        bend the edge)."""
        if not self.point_mode.value:
            return
        board, scene = self.view.board, self.view.client.scene
        for name in self.view.session.pattern.piece_names:
            points, middles = self.editor.handles(name)
            for kind, pts, color in (("point", points, (150, 30, 30)), ("middle", middles, (30, 90, 200))):
                for i, at in enumerate(board.to_board(name, pts) + [0, 0, 0.01]):
                    selected = kind == "point" and self.selected_point == (name, i)
                    h = scene.add_icosphere(
                        f"/board/handles/{name}/{kind}{i}", HANDLE_RADIUS_M * (1.5 if selected else 1.0),
                        (250, 180, 0) if selected else color, position=tuple(at), subdivisions=1,
                    )  # fmt: skip
                    h.on_drag()(self._handle_drag(name, kind, i))
                    if kind == "point":
                        h.on_click()(self._point_clicked(name, i))

    def show_corners(self) -> None:
        """The piece being drawn: its corners so far, joined."""
        scene = self.view.client.scene
        if not self.corners:
            scene.remove_by_name("/new_piece")
            return
        pts = np.array(self.corners) + [0, 0, 0.008]
        ring = np.vstack([pts, pts[:1]]) if len(pts) > 2 else pts
        if len(ring) > 1:
            self.view.polyline("/new_piece", ring, (200, 60, 20))
        else:
            scene.add_point_cloud("/new_piece", pts.astype(np.float32), (200, 60, 20), point_size=0.02)

    # -- clicks and drags on the board ------------------------------------------------------------------------
    def scene_clicked(self, event) -> None:  # noqa: ANN001
        """A corner of the piece being drawn, where the click's ray meets the board."""
        if not self.piece_mode.value or event.ray_origin is None:
            return
        hit = self.view.board.on_board(np.asarray(event.ray_origin), np.asarray(event.ray_direction))
        if hit is None:
            return
        self.corners.append(hit)
        self.show_corners()

    def piece_click_handler(self, piece: str):  # noqa: ANN201
        """A click on a piece: in point mode, a point added on the nearest edge; in sew mode, an edge picked."""

        def handler(event) -> None:  # noqa: ANN001
            if not (self.sew_mode.value or self.point_mode.value):
                return
            board = self.view.board
            hit = board.on_board(np.asarray(event.ray_origin), np.asarray(event.ray_direction))
            if hit is None:
                return
            cm = board.to_piece(piece, hit[None])[0]
            edge = EdgeRef(piece, self.editor.nearest_edge(piece, cm))
            if self.point_mode.value:
                self.apply(lambda: self.editor.insert_point(piece, edge.edge, cm))
                return
            if not self.sewing:
                self.sewing = [edge]
                self.view.status_line(f"Edge {edge} picked: click the edge to sew it to.")
                return
            first, self.sewing = self.sewing[0], []
            self.apply(lambda: self.editor.sew(first, edge))

        return handler

    def _handle_drag(self, piece: str, kind: str, index: int):  # noqa: ANN202
        """A point handle moves the point; an edge's middle handle bends the edge (applied on release)."""
        pressed: list[np.ndarray] = []

        async def handler(event) -> None:  # noqa: ANN001
            hit = self.view.board.on_board(*self.view.ray(event))
            if hit is None:
                return
            if event.phase == "start":
                pressed[:] = [hit]
                return
            event.target.position = tuple(hit + [0, 0, 0.01])  # follows the pointer while dragged
            if event.phase != "end":
                return
            if pressed and np.linalg.norm(hit - pressed[0]) < CLICK_SLOP_M:  # a shaky click: nothing moves
                self.view.rebuild_scene()
                return
            cm = self.view.board.to_piece(piece, hit[None])[0]
            if kind == "point":
                self.apply(lambda: self.editor.move_point(piece, index, cm))
            else:
                self.apply(lambda: self.editor.curve_edge(piece, index, cm))

        return handler

    def _point_clicked(self, piece: str, index: int):  # noqa: ANN202
        def handler(_event) -> None:  # noqa: ANN001
            self.selected_point = None if self.selected_point == (piece, index) else (piece, index)
            self.view.rebuild_scene()

        return handler

    # -- buttons ----------------------------------------------------------------------------------------------
    def _delete_point(self) -> None:
        if self.selected_point is None:
            self.view.notify("No point selected", "Tick Edit points and click a red point first.", "yellow")
            return
        (piece, index), self.selected_point = self.selected_point, None
        self.apply(lambda: self.editor.delete_point(piece, index))

    def _close_piece(self) -> None:
        if len(self.corners) < 3:
            self.view.notify("A piece needs 3 corners", "Tick 'Draw a piece' and click its corners on the board.",
                             "yellow")  # fmt: skip
            return
        cm = np.array(self.corners)[:, :2] / self.view.board.scale
        self.corners = []
        self.show_corners()
        self.apply(lambda: self.editor.add_piece(cm))

    def _seam_names(self) -> list[str]:
        names = [f"{k}: {s.a} to {s.b}" for k, s in enumerate(self.editor.pattern.seams)]
        return names or ["(no seams)"]

    def _seam_action(self, action) -> None:  # noqa: ANN001 - an editor call on one edge of the seam
        seams = self.editor.pattern.seams
        k = int(self.seam_choice.value.split(":")[0]) if self.seam_choice.value[0].isdigit() else -1
        if not 0 <= k < len(seams):
            self.view.notify("No seam chosen", "Sew two edges first (Sew: click two edges).", "yellow")
            return
        self.apply(lambda: action(seams[k].a))

    def _download_pattern(self) -> None:
        from ..pattern import save_pattern

        with tempfile.TemporaryDirectory() as d:
            path = Path(d) / f"{self.editor.pattern.name}.json"
            save_pattern(self.editor.pattern, path)
            self.view.client.send_file_download(path.name, path.read_bytes(), save_immediately=True)
