"""What one browser tab sees and does: its scene (the body, the pattern board, strokes, the garment), its panel
of tools, and its `DressingSession`. Thin: what a button or a stroke does is a session or library call.

Drawing: press and drag on a pattern piece draws a pattern stroke; the next press-drag on the body draws its
partner (pairs are numbered and coloured alike). Dragging on empty space turns the view. viser reports a drag as
the pointer's position on a camera-facing plane; the view turns it into a ray from the camera and hits the
board's plane or the body itself (`Surface.cast`), so strokes lie on what was drawn on.
"""

from __future__ import annotations

import tempfile
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..errors import ComputationError, InputError
from .board import BoardLayout
from .drag_history import DragHistory
from .dragger import Dragger
from .editor import PatternEditor
from .editor_view import EditorTools
from .framing import frame
from .session import DressingSession, pair_color
from .worker import Cancelled

if TYPE_CHECKING:
    from .server import App

#: Largest file accepted from the browser, bytes (the issue's 50 MB).
MAX_UPLOAD_BYTES = 50 * 2**20
BODY_COLOR = (214, 190, 170)
GARMENT_COLOR = (70, 95, 160)
PIECE_COLOR = (246, 240, 228)
BODY_SUFFIXES = (".obj", ".glb", ".gltf", ".ply")
PATTERN_SUFFIXES = (".json", ".svg")


@dataclass
class _Drawing:
    """A stroke being drawn: on a piece (its name) or on the body (piece None); points so far."""

    piece: str | None
    points: list[np.ndarray] = field(default_factory=list)


class ClientView:
    """What one browser tab sees and does: its scene, its panel, its session."""

    def __init__(self, app: App, client) -> None:  # noqa: ANN001 - a viser ClientHandle
        self.app = app
        self.client = client
        self.session = DressingSession(app.body, app.pattern, app.strokes)
        self.tools = EditorTools(self, PatternEditor(app.pattern))
        self.board = BoardLayout.of(app.pattern)
        self.drawing: _Drawing | None = None
        self.cancel = threading.Event()
        self.busy = False
        self.outcome = ""
        self.jobs_done = 0
        self.dragging = None  # the DragSession of the garment dressed last (with drag_history, dragger)
        self._syncing = False
        self._stroke_handles: list = []
        self._build_panel()
        self.tools.refresh_panel()
        self._build_scene()
        self._redraw_strokes()
        client.scene.on_click()(self.tools.scene_clicked)  # corners of a piece being drawn (once: scenes are rebuilt)
        self._framed = False
        client.camera.on_update(self._first_camera_report)
        if client.camera.update_timestamp:  # it reported while this view was being built
            self._first_camera_report(client.camera)

    @property
    def editor(self) -> PatternEditor:
        """The pattern being edited, with its undo history."""
        return self.tools.editor

    # -- scene ------------------------------------------------------------------------------------------------
    def _first_camera_report(self, camera) -> None:  # noqa: ANN001 - a viser CameraHandle
        """The tab's size is known from its camera's first report: frame the scene in it, once (a later resize or
        orbit is the user's; "Fit view" frames again)."""
        if not self._framed:
            self._framed = self.fit_view()

    def fit_view(self) -> bool:
        """Frame the body and the pattern board whole in the canvas left of the control panel (`framing.frame`).
        Returns False, doing nothing, for a tab that reports no canvas size (a hidden one)."""
        cam = self.client.camera
        if not (cam.image_width > 0 and cam.image_height > 0):
            return False
        mesh = self.session.body.mesh
        boxes = [mesh.vertices.min(axis=0), mesh.vertices.max(axis=0)]
        board = self.board.bounds()
        if board is not None:
            boxes += list(board)
        corners = np.array(boxes)
        f = frame(corners.min(axis=0), corners.max(axis=0), cam.fov, cam.image_width, cam.image_height)
        with self.client.atomic():
            cam.position = tuple(f.position)
            cam.look_at = tuple(f.look_at)
        return True

    def _build_scene(self) -> None:
        from ..pattern import mesh_pattern

        scene = self.client.scene
        mesh = self.session.body.mesh
        self.body_handle = scene.add_mesh_simple(
            "/body", mesh.vertices.astype(np.float32), mesh.faces.astype(np.uint32), color=BODY_COLOR
        )
        self.body_handle.on_drag()(self._on_body_drag)
        self.piece_handles = {}
        if not self.session.pattern.pieces:  # a new, empty pattern: only the body, until a piece is drawn
            return
        pm = mesh_pattern(self.session.pattern, edge_length=8.0)
        for k, name in enumerate(pm.piece_names):
            f0, f1 = pm.piece_faces[k]
            v0, v1 = pm.piece_vertices[k]
            verts = self.board.to_board(name, pm.vertices_cm[v0:v1])
            faces = pm.faces[f0:f1] - v0
            h = scene.add_mesh_simple(
                f"/board/{name}", verts.astype(np.float32), faces.astype(np.uint32), color=PIECE_COLOR, side="double"
            )
            h.on_drag()(self._piece_drag_handler(name))
            h.on_click()(self.tools.piece_click_handler(name))
            self.piece_handles[name] = h
            piece = self.session.pattern.piece(name)
            outline = np.concatenate([piece.sample_edge(e)[:-1] for e in range(piece.n_edges)])
            ring = self.board.to_board(name, outline) + [0, 0, 0.002]
            scene.add_line_segments(
                f"/board/{name}/outline", np.stack([ring, np.roll(ring, -1, axis=0)], axis=1), (60, 60, 60),
                thickness=2.0, thickness_units="screen",
            )  # fmt: skip
            low, high = piece.bounds
            top = self.board.to_board(name, np.array([[(low[0] + high[0]) / 2, high[1]]]))[0]
            scene.add_label(f"/board/{name}/name", name, position=tuple(top + [0, 0.03, 0]), anchor="bottom-center")
        self.tools.draw()

    def rebuild_scene(self) -> None:
        self.client.scene.reset()
        self._stroke_handles = []  # gone with the scene
        self._build_scene()
        self._redraw_strokes()

    def _sync_pair_choice(self) -> str:
        """The Pair list made to name the pairs there are; returns the chosen one ("(none)" without pairs)."""
        names = [str(p.id) for p in self.session.pairs] or ["(none)"]
        chosen = self.pair_choice.value if self.pair_choice.value in names else names[-1]
        self._syncing = True  # setting the list's value calls its update, which must not redraw mid-redraw
        try:
            if tuple(self.pair_choice.options) != tuple(names):
                self.pair_choice.options = names
            if self.pair_choice.value != chosen:
                self.pair_choice.value = chosen
        finally:
            self._syncing = False
        return chosen

    def _redraw_strokes(self) -> None:
        if self._syncing:
            return
        chosen = self._sync_pair_choice()
        scene = self.client.scene
        for handle in self._stroke_handles:
            handle.remove()
        self._stroke_handles = []
        s = self.session
        for pair in s.pairs:
            color = pair_color(pair.id)
            width = 8.0 if str(pair.id) == chosen else 4.0  # the chosen pair stands out
            on_board = self.board.to_board(pair.pattern.piece, s.pattern_points_on_piece(pair)) + [0, 0, 0.006]
            on_body = pair.body.surface_points + s.surface.normals_at(pair.body.faces) * 0.004
            for name, pts in ((f"/strokes/{pair.id}/pattern", on_board), (f"/strokes/{pair.id}/body", on_body)):
                self._stroke_handles.append(self.polyline(name, pts, color, width))
            self._stroke_handles.append(
                scene.add_label(f"/strokes/{pair.id}/label", str(pair.id), position=tuple(on_body[0]))
            )
        for pair in s.garment_pairs:
            color = pair_color(pair.id)
            on_board = self.board.to_board(pair.pattern.piece, pair.pattern.points) + [0, 0, 0.006]
            self._stroke_handles.append(self.polyline(f"/rewrap/{pair.id}/pattern", on_board, color))
            self._stroke_handles.append(
                self.polyline(f"/rewrap/{pair.id}/garment", pair.body.surface_points + [0, 0, 0.004], color)
            )
        shown = s.waiting if self.laser.value else s.waiting[-1:]
        for k, stroke in enumerate(shown):
            pts = self.board.to_board(stroke.piece, self._piece_points(stroke)) + [0, 0, 0.006]
            self._stroke_handles.append(self.polyline(f"/strokes/pending{k}", pts, (40, 40, 40)))
        self.status_line()

    def _piece_points(self, stroke) -> np.ndarray:  # noqa: ANN001 - a PatternStroke in file coordinates
        return self.session.pattern.file_to_piece(stroke.piece, stroke.points)

    def polyline(self, name: str, pts: np.ndarray, color: tuple[int, int, int], width: float = 4.0):  # noqa: ANN202
        seg = np.stack([pts[:-1], pts[1:]], axis=1)
        return self.client.scene.add_line_segments(name, seg, color, thickness=width, thickness_units="screen")

    # -- drawing ----------------------------------------------------------------------------------------------
    def ray(self, event) -> tuple[np.ndarray, np.ndarray]:  # noqa: ANN001
        """The pointer's ray at a drag event: from the camera through the reported point."""
        eye = np.asarray(event.client.camera.position, dtype=np.float64)
        through = np.asarray(event.end_position, dtype=np.float64)
        return eye, through - eye

    def _piece_drag_handler(self, piece: str):  # noqa: ANN202
        async def handler(event) -> None:  # noqa: ANN001
            if event.phase == "start":
                self.drawing = _Drawing(piece, [np.asarray(event.start_position, dtype=np.float64)])
                return
            if self.drawing is None or self.drawing.piece != piece:
                return
            hit = self.board.on_board(*self.ray(event))
            if hit is not None:
                self.drawing.points.append(hit)
            if event.phase == "end":
                drawn, self.drawing = self.drawing, None
                self._finish_pattern_stroke(drawn)

        return handler

    async def _on_body_drag(self, event) -> None:  # noqa: ANN001
        if self.laser.value:
            return self._laser_drag(event)
        if event.phase == "start":
            self.drawing = _Drawing(None, [np.asarray(event.start_position, dtype=np.float64)])
            return
        if self.drawing is None or self.drawing.piece is not None:
            return
        eye, direction = self.ray(event)
        hit = self.session.surface.cast(eye[None], direction[None], hit="first")
        if hit.hit.all():
            self.drawing.points.append(hit.points[0])
        if event.phase == "end":
            drawn, self.drawing = self.drawing, None
            self._finish_body_stroke(drawn)

    def _laser_drag(self, event) -> None:  # noqa: ANN001
        """A laser stroke: the pointer's rays, kept whole (origin and direction) for both of their hits."""
        eye = np.asarray(event.client.camera.position, dtype=np.float64)
        if event.phase == "start":
            self.drawing = _Drawing(None, [np.r_[eye, np.asarray(event.start_position) - eye]])
            return
        if self.drawing is None or self.drawing.piece is not None:
            return
        self.drawing.points.append(np.r_[self.ray(event)])
        if event.phase == "end":
            rays, self.drawing = np.array(self.drawing.points), None
            if len(rays) >= 2:
                try:
                    self.session.draw_laser_stroke(rays)
                except InputError as e:
                    self.notify("Laser stroke not kept", e.message, "yellow")
            self._redraw_strokes()

    def _finish_pattern_stroke(self, drawn: _Drawing) -> None:
        pts = np.array(drawn.points)
        if len(pts) < 2:
            return
        local = self.board.to_piece(drawn.piece, pts)
        try:
            self.session.draw_pattern_stroke(drawn.piece, self.session.pattern.piece_to_file(drawn.piece, local))
        except InputError as e:
            self.notify("That stroke was not kept", e.message, "red")
        self._redraw_strokes()

    def _finish_body_stroke(self, drawn: _Drawing) -> None:
        pts = np.array(drawn.points)
        if len(pts) < 2:
            return
        try:
            self.session.draw_body_stroke(pts)
        except InputError as e:
            self.notify("Draw on the pattern first", e.message, "yellow")
        self._redraw_strokes()

    # -- panel ------------------------------------------------------------------------------------------------
    def _build_panel(self) -> None:
        gui = self.client.gui
        self.status = gui.add_markdown("")
        with gui.add_folder("Strokes"):
            gui.add_button("Undo", icon="arrow-back-up").on_click(lambda _: self._edit(self.session.undo))
            gui.add_button("Redo", icon="arrow-forward-up").on_click(lambda _: self._edit(self.session.redo))
            gui.add_button("Suggest strokes").on_click(lambda _: self._edit(self.session.suggest))
            gui.add_button("Clear strokes").on_click(lambda _: self._edit(self.session.clear))
            self.pair_choice = gui.add_dropdown("Pair", ["(none)"])
            self.pair_choice.on_update(lambda _: self._redraw_strokes())
            gui.add_button("Delete pair").on_click(lambda _: self._pair_action(redraw=False))
            gui.add_button(
                "Redraw pair", hint="removes the pair: the next pattern and body strokes drawn take its number"
            ).on_click(lambda _: self._pair_action(redraw=True))
            self.laser = gui.add_checkbox(
                "Laser (front and back)", False,
                hint="one stroke across the body lands on its front and its back, for the last two pattern strokes",
            )  # fmt: skip
            self.laser.on_update(lambda _: self._redraw_strokes())
        with gui.add_folder("View"):
            seams = gui.add_checkbox("Show seams", True)
            seams.on_update(lambda _: self.tools.show_seams(seams.value))
            pieces = self.session.pattern.piece_names
            self.flip_choice = gui.add_dropdown("Piece", pieces, initial_value=pieces[0])
            gui.add_button("Turn piece over").on_click(
                lambda _: self.tools.apply(lambda: self.editor.flip(self.flip_choice.value))
            )
            gui.add_button("Fit view", hint="the body and the pattern whole, beside this panel").on_click(
                lambda _: self.fit_view()
            )
        with gui.add_folder("Edit the pattern", expand_by_default=False):
            self.tools.build_panel(gui)
        with gui.add_folder("Wrap"):
            self.edge = gui.add_number(
                "Mesh edge (cm)", self.app.options.edge_length, min=0.5, max=5.0, step=0.5,
                hint="the garment's triangle size: larger is faster to wrap and to drag, with coarser folds",
            )  # fmt: skip
            self.wrap_button = gui.add_button("Wrap", color="blue", icon="shirt")
            self.wrap_button.on_click(lambda _: self._start_wrap())
            self.cancel_button = gui.add_button("Cancel wrap", disabled=True)
            self.cancel_button.on_click(lambda _: self.cancel.set())
        with gui.add_folder("Drag the garment"):
            self.pin_mode = gui.add_checkbox("Click to pin / unpin", False)
            self.rewrap_mode = gui.add_checkbox(
                "Draw on the garment (re-wrap)", False,
                hint="a stroke on a pattern piece, then one on the garment where that cloth should go; then Re-wrap",
            )  # fmt: skip
            gui.add_button("Re-wrap").on_click(lambda _: self._start_rewrap())
            gui.add_button("Unpin all").on_click(lambda _: self._unpin_all())
            gui.add_button("Undo drag").on_click(lambda _: self._drag_history(undo=True))
            gui.add_button("Redo drag").on_click(lambda _: self._drag_history(undo=False))
            self.strain_box = gui.add_checkbox(
                "Show strain",
                False,
                hint="the garment coloured by stretch: yellow at the quality target, red at twice it",
            )
            self.strain_box.on_update(lambda _: self.show_strain())
            self.drag_rate = gui.add_markdown("Wrap first; then press and drag on the garment.")
        with gui.add_folder("Files"):
            gui.add_upload_button("Open body (OBJ, GLB, PLY)").on_upload(self._upload_body)
            gui.add_upload_button("Open pattern (JSON, SVG)").on_upload(self._upload_pattern)
            gui.add_upload_button("Open strokes (JSON)").on_upload(self._upload_strokes)
            gui.add_button("Save strokes").on_click(lambda _: self._download_strokes())
            gui.add_button("Save garment (GLB, OBJ, report)").on_click(lambda _: self._download_garment())
            gui.add_button("Save drags (JSON)").on_click(lambda _: self._download_drags())

    def _unpin_all(self) -> None:
        if self.dragging is not None and not self.dragger.busy:
            self.drag_history.unpin_all()
            self._show_pins()

    def status_line(self, extra: str = "") -> None:
        s = self.session
        lines = [f"**{s.pattern.name}** on the body: {len(s.pairs)} stroke pair(s)."]
        if s.garment_pairs:
            lines.append(f"{len(s.garment_pairs)} re-wrap stroke pair(s) drawn on the garment.")
        if self.laser.value:
            if len(s.waiting) < 2:
                lines.append("Laser: draw a stroke on a front piece, then one on a back piece.")
            else:
                lines.append(f"Laser: now one stroke across the body for *{s.waiting[0].piece}* (front) and "
                             f"*{s.waiting[1].piece}* (back).")  # fmt: skip
        elif s.pending is not None:
            lines.append(f"Stroke {s.next_id()} drawn on *{s.pending.piece}*: now draw its partner on the body.")
        else:
            lines.append("Draw a stroke on a pattern piece, then its partner on the body.")
        if extra:
            lines.append(extra)
        self.status.content = "\n\n".join(lines)

    def _pair_action(self, *, redraw: bool) -> None:
        if not self.pair_choice.value.isdigit():
            self.notify("No pair chosen", "Draw a stroke pair first, then choose it in the Pair list.", "yellow")
            return
        self._edit(lambda: self.session.delete(int(self.pair_choice.value), redraw=redraw))

    def _edit(self, action) -> None:  # noqa: ANN001
        try:
            action()
        except InputError as e:
            self.notify("Could not do that", e.message, "red")
        self._redraw_strokes()

    def notify(self, title: str, body: str, color: str | None = None) -> None:
        self.client.add_notification(title, body, color=color, auto_close_seconds=8.0)

    # -- wrap and re-wrap ----------------------------------------------------------------------------------
    def _start_wrap(self) -> None:
        from dataclasses import replace

        s = self.session
        strokes = s.wrap_strokes()
        if not len(strokes):
            self.notify("No strokes yet", "Draw at least one stroke pair (pattern, then body) to wrap.", "yellow")
            return
        params = replace(self.app.options, edge_length=float(self.edge.value)).wrap_params(s.body, s.pattern)
        self._start_job(
            "Wrapping",
            lambda say: self.app.worker.wrap(s.body, s.pattern, strokes, params, cancel=self.cancel, progress=say),
            self._wrapped,
        )  # fmt: skip

    def _start_rewrap(self) -> None:
        s, d = self.session, self.dragging
        if d is None or not s.garment_pairs:
            self.notify("Nothing to re-wrap", "Wrap first; then draw a stroke on the pattern and where it should "
                        "go on the garment (Draw on the garment ticked).", "yellow")  # fmt: skip
            return
        garment, strokes, pins = d.garment(), s.garment_strokes(), d.positions[d.pinned].copy()
        self._start_job(
            "Re-wrapping", lambda _say: self.app.worker.rewrap(s.body, garment, strokes, pins, cancel=self.cancel),
            self._rewrapped,
        )  # fmt: skip

    def _start_job(self, title: str, compute, done) -> None:  # noqa: ANN001
        """Run `compute(progress)` (a wrap or re-wrap in the worker; `progress(stage)` names the stage it is in) in
        a thread, with its stage and elapsed time shown and Cancel armed; `done(result)` takes what it gives."""
        if self.busy:
            return
        self.busy = True
        self.cancel.clear()
        self.wrap_button.disabled = True
        self.cancel_button.disabled = False
        threading.Thread(target=self._job, args=(title, compute, done), daemon=True, name="kitsuke-app-job").start()

    def _job(self, title: str, compute, done) -> None:  # noqa: ANN001
        note = self.client.add_notification(title, "0 s", loading=True, with_close_button=False)
        ticking = threading.Event()

        stage = [""]  # the wrap's stage now, as its child process says

        def tick() -> None:  # the stage and the elapsed time, so that a long wrap is seen to be working
            t0 = time.monotonic()
            while not ticking.wait(0.5):
                now = f"{stage[0]}, " if stage[0] else ""
                note.body = f"{now}{time.monotonic() - t0:.0f} s (Cancel wrap stops it)"

        ticker = threading.Thread(target=tick, daemon=True)
        ticker.start()
        try:
            result = compute(lambda name: stage.__setitem__(0, name))
        except Cancelled:
            self._job_ended(note, ticker, ticking, f"{title} cancelled", "Nothing changed.", "yellow")
            return
        except (InputError, ComputationError) as e:
            reason = e.message if isinstance(e, InputError) else f"{e.stage}: {e.message}"
            self._job_ended(note, ticker, ticking, f"{title} failed", reason, "red")
            return
        title, body, color = done(result)
        self._job_ended(note, ticker, ticking, title, body, color)
        self.status_line(body)

    def _wrapped(self, garment) -> tuple[str, str, str]:  # noqa: ANN001 - a DressedGarment
        from ..dressing import target_misses

        self.session.garment = garment
        self.session.garment_changed()
        self._start_drag(garment)
        misses = target_misses(garment)
        verdict = "all quality targets met" if not misses else "missed: " + "; ".join(misses)
        summary = f"Dressed: {garment.n_vertices} vertices, {garment.timings.get('wrap', 0.0):.1f} s; {verdict}."
        return "Dressed", summary, "green" if not misses else "yellow"

    def _rewrapped(self, garment) -> tuple[str, str, str]:  # noqa: ANN001 - a GarmentFile
        self.session.garment_changed()
        self._start_drag(garment)
        self._redraw_strokes()
        return "Re-wrapped", f"Re-wrapped: {len(garment.positions)} vertices.", "green"

    # -- drag and pins ----------------------------------------------------------------------------------------
    def _start_drag(self, garment) -> None:  # noqa: ANN001 - a DressedGarment
        from ..dressing import DragSession

        self.dragging = DragSession(self.session.body, garment)
        self.drag_history = DragHistory(self.dragging)
        self.dragger = Dragger(self)
        self._show_garment()

    def _show_garment(self) -> None:
        """(Re)build the garment's scene node from the drag session (a release may refine its mesh)."""
        d = self.dragging
        self.garment_handle = self.client.scene.add_mesh_simple(
            "/garment", d.positions.astype(np.float32), d.model.faces.astype(np.uint32),
            color=GARMENT_COLOR, side="double",
        )  # fmt: skip
        self.garment_handle.on_drag()(self._on_garment_drag)
        self.garment_handle.on_click()(self._on_garment_click)
        self._shown_vertices = d.n_vertices
        self._show_pins()
        self.show_strain()

    def show_strain(self) -> None:
        """The strain map in place of the plain garment while it is at rest and Show strain is ticked (a drag
        shows the plain garment: only its vertices stream)."""
        import trimesh

        from ..metrics import QualityTargets, vertex_strain
        from .strain_map import strain_colors

        d = self.dragging
        if d is None:
            return
        on = self.strain_box.value and d.grabbed is None
        if on:
            g = d.garment()
            colors = strain_colors(
                vertex_strain(g.positions, g.faces, g.rest_edge_lengths), QualityTargets().max_strain
            )
            mesh = trimesh.Trimesh(g.positions, g.faces, vertex_colors=colors, process=False)
            self.client.scene.add_mesh_trimesh("/garment_strain", mesh)
        else:
            self.client.scene.remove_by_name("/garment_strain")
        self.garment_handle.visible = not on

    def _show_pins(self) -> None:
        d = self.dragging
        pts = d.positions[d.pinned]
        if len(pts):
            self.client.scene.add_point_cloud(
                "/pins", pts.astype(np.float32), (255, 200, 0), point_size=0.02, point_shape="circle"
            )
        else:
            self.client.scene.remove_by_name("/pins")

    def push_positions(self) -> None:
        """Send the garment's vertices (only them) to the browser."""
        d = self.dragging
        if d.n_vertices != self._shown_vertices:
            self._show_garment()
        else:
            self.garment_handle.vertices = d.positions.astype(np.float32)

    async def _on_garment_drag(self, event) -> None:  # noqa: ANN001
        if self.rewrap_mode.value:
            return self._garment_stroke_drag(event)
        if event.phase == "start":
            self.dragger.submit("grab", np.asarray(event.start_position, dtype=np.float64))
        elif event.phase == "update":
            self.dragger.submit("move", self._body_target(event))
        else:
            self.dragger.submit("release", None)

    def _garment_stroke_drag(self, event) -> None:  # noqa: ANN001
        """A re-wrap stroke drawn on the garment as it is now."""
        from ..geometry import TriMesh
        from ..geometry.surface import Surface

        if event.phase == "start":
            d = self.dragging
            self._cloth_surface = Surface(TriMesh(d.positions.copy(), d.model.faces))
            self.drawing = _Drawing(None, [np.asarray(event.start_position, dtype=np.float64)])
            return
        if self.drawing is None or self.drawing.piece is not None:
            return
        eye, direction = self.ray(event)
        hit = self._cloth_surface.cast(eye[None], direction[None], hit="first")
        if hit.hit.all():
            self.drawing.points.append(hit.points[0])
        if event.phase == "end":
            pts, self.drawing = np.array(self.drawing.points), None
            if len(pts) >= 2:
                try:
                    self.session.draw_garment_stroke(pts, self._cloth_surface)
                except InputError as e:
                    self.notify("Draw on the pattern first", e.message, "yellow")
            self._redraw_strokes()

    def _body_target(self, event) -> np.ndarray:  # noqa: ANN001
        """Where the pointer is on the body (its ray's first hit), or the body point nearest the pointer's place
        on the camera-facing plane when the ray misses the body."""
        eye, direction = self.ray(event)
        hit = self.session.surface.cast(eye[None], direction[None], hit="first")
        if hit.hit.all():
            return hit.points[0]
        return self.session.surface.closest(np.asarray(event.end_position, dtype=np.float64)[None]).points[0]

    async def _on_garment_click(self, event) -> None:  # noqa: ANN001
        if not self.pin_mode.value or self.dragger.busy:
            return
        from ..geometry import TriMesh
        from ..geometry.surface import Surface

        d = self.dragging
        cloth = Surface(TriMesh(d.positions, d.model.faces))
        hit = cloth.cast(np.asarray(event.ray_origin)[None], np.asarray(event.ray_direction)[None], hit="first")
        if not hit.hit.all():
            return
        self.drag_history.toggle_pin(int(d.model.faces[hit.faces[0]][np.argmax(hit.barycentric[0])]))
        self._show_pins()

    def _drag_history(self, undo: bool) -> None:
        if self.dragging is None or self.dragger.busy:
            return
        if self.drag_history.undo() if undo else self.drag_history.redo():
            self.push_positions()
            self._show_pins()
            self.show_strain()

    def _job_ended(  # noqa: PLR0913
        self,
        note,  # noqa: ANN001 - a viser NotificationHandle
        ticker: threading.Thread,
        ticking: threading.Event,
        title: str,
        body: str,
        color: str,
    ) -> None:
        ticking.set()
        ticker.join()  # its last update must not land on the removed notice
        note.remove()
        self.notify(title, body, color)
        self.outcome = f"{title}: {body}"  # the last wrap's or re-wrap's, as said to the user
        self.jobs_done += 1
        self.busy = False
        self.wrap_button.disabled = False
        self.cancel_button.disabled = True

    # -- files ------------------------------------------------------------------------------------------------
    def _received(self, event, suffixes: tuple[str, ...]) -> Path | None:  # noqa: ANN001
        """An uploaded file written to this session's own folder under a fixed name (never a browser's path),
        or None after telling the user why not."""
        f = event.target.value
        suffix = Path(f.name).suffix.lower()
        if suffix not in suffixes:
            self.notify("Not opened", f"{f.name}: expected {', '.join(suffixes)}", "red")
            return None
        if len(f.content) > MAX_UPLOAD_BYTES:
            self.notify("Not opened", f"{f.name}: larger than {MAX_UPLOAD_BYTES // 2**20} MB", "red")
            return None
        path = Path(self.app.uploads.name) / f"{self.client.client_id}-upload{suffix}"
        path.write_bytes(f.content)
        return path

    def _opened(self, event, suffixes: tuple[str, ...], read, problem: str):  # noqa: ANN001, ANN202
        """What `read(path)` makes of an uploaded file, or None after telling the user why not."""
        path = self._received(event, suffixes)
        if path is None:
            return None
        try:
            return read(path)
        except InputError as e:
            self.notify(problem, f"{event.target.value.name}: {e.message}", "red")
            return None

    def _upload_body(self, event) -> None:  # noqa: ANN001
        from ..body import load_body

        body = self._opened(event, BODY_SUFFIXES, load_body, "Not a body this app can use")
        if body is not None:
            self._replace(body=body)

    def _upload_pattern(self, event) -> None:  # noqa: ANN001
        from ..pattern import load_pattern

        pattern = self._opened(event, PATTERN_SUFFIXES, load_pattern, "Not a pattern this app can use")
        if pattern is not None:
            self._replace(pattern=pattern)

    def _upload_strokes(self, event) -> None:  # noqa: ANN001
        from ..dressing import read_strokes

        def load(path: Path) -> bool:
            self.session.load_strokes(read_strokes(path))
            return True

        if self._opened(event, (".json",), load, "Strokes not loaded"):
            self._redraw_strokes()

    def pattern_edited(self, pattern) -> None:  # noqa: ANN001 - a Pattern
        """The editor changed the pattern: the board rebuilt, the strokes that still lie on their pieces kept."""
        self._replace(pattern=pattern, keep_editor=True)

    def _replace(self, *, body=None, pattern=None, keep_editor: bool = False) -> None:  # noqa: ANN001
        """A new body or pattern: a fresh session, the scene rebuilt. An edited pattern keeps the stroke pairs
        that still lie on its pieces; a new body or an opened pattern starts without strokes."""
        s = self.session
        strokes = s.strokes() if keep_editor and body is None and len(s.strokes()) else None
        try:
            self.session = DressingSession(body or s.body, pattern or s.pattern, strokes)
        except InputError:
            self.session = DressingSession(body or s.body, pattern or s.pattern)
            self.notify("Strokes dropped", "the edit moved a piece a stroke was drawn on", "yellow")
        if not keep_editor:
            self.tools.editor = PatternEditor(self.session.pattern)
        self.board = BoardLayout.of(self.session.pattern)
        self.client.scene.reset()
        self._stroke_handles = []  # gone with the scene
        self._build_scene()
        names = self.session.pattern.piece_names
        if names and hasattr(self, "flip_choice"):
            current = self.flip_choice.value
            self.flip_choice.options = names
            self.flip_choice.value = current if current in names else names[-1]
        self.tools.refresh_panel()
        self._redraw_strokes()

    def _dressed(self, hint: str) -> bool:
        """Whether a garment is dressed; if not, the user is told `hint`."""
        if self.dragging is None:
            self.notify("Nothing dressed yet", hint, "yellow")
        return self.dragging is not None

    def _download_strokes(self) -> None:
        from ..dressing import strokes_to_json

        self.client.send_file_download(
            "strokes.json", strokes_to_json(self.session.strokes()).encode(), save_immediately=True
        )

    def _download_drags(self) -> None:
        """The pins and drags made so far, as a drags file that `kitsuke drag --drags` replays."""
        from ..dressing import drags_to_json

        if not self._dressed("Wrap, pin and drag first, then save the drags."):
            return
        self.client.send_file_download(
            "drags.json", drags_to_json(self.drag_history.drags()).encode(), save_immediately=True
        )

    def _download_garment(self) -> None:
        """The garment as it is now (dragged, pinned) with its quality report."""
        from .._files import write_json_atomic
        from ..dressing.export import write_garment_glb, write_garment_obj

        if not self._dressed("Wrap first, then save the garment."):
            return
        garment, body = self.dragging.garment(), self.session.body.mesh
        with tempfile.TemporaryDirectory() as d:
            paths = [Path(d) / n for n in ("garment.glb", "garment.obj", "garment_report.json")]
            write_garment_glb(garment, paths[0], body=body)
            write_garment_obj(garment, paths[1])
            write_json_atomic(paths[2], self.dragging.report().to_dict())
            for p in paths:
                self.client.send_file_download(p.name, p.read_bytes(), save_immediately=True)
