"""The browser app on viser: one scene with the body and the pattern board beside it, a panel of tools, and a
`DressingSession` per browser tab. Thin: what a button or a stroke does is a session or library call.

Drawing: press and drag on a pattern piece draws a pattern stroke; the next press-drag on the body draws its
partner (pairs are numbered and coloured alike). Dragging on empty space turns the view. viser reports a drag as
the pointer's position on a camera-facing plane; the server turns it into a ray from the camera and hits the
board's plane or the body itself (`Surface.cast`), so strokes lie on what was drawn on.

app = App(body, pattern)                 # not yet listening
app.start(host="127.0.0.1", port=8080)   # the URL: app.url
"""

from __future__ import annotations

import os
import tempfile
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import ComputationError, InputError
from .board import BoardLayout
from .session import DressingSession, pair_color
from .worker import Cancelled, WrapWorker

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
        self.board = BoardLayout.of(app.pattern)
        self.drawing: _Drawing | None = None
        self.cancel = threading.Event()
        self.busy = False
        self._build_scene()
        self._build_panel()
        self._redraw_strokes()

    # -- scene ------------------------------------------------------------------------------------------------
    def _build_scene(self) -> None:
        from ..pattern import mesh_pattern

        scene = self.client.scene
        mesh = self.session.body.mesh
        self.body_handle = scene.add_mesh_simple(
            "/body", mesh.vertices.astype(np.float32), mesh.faces.astype(np.uint32), color=BODY_COLOR
        )
        self.body_handle.on_drag()(self._on_body_drag)
        pm = mesh_pattern(self.session.pattern, edge_length=8.0)
        self.piece_handles = {}
        for k, name in enumerate(pm.piece_names):
            f0, f1 = pm.piece_faces[k]
            v0, v1 = pm.piece_vertices[k]
            verts = self.board.to_board(name, pm.vertices_cm[v0:v1])
            faces = pm.faces[f0:f1] - v0
            h = scene.add_mesh_simple(
                f"/board/{name}", verts.astype(np.float32), faces.astype(np.uint32), color=PIECE_COLOR, side="double"
            )
            h.on_drag()(self._piece_drag_handler(name))
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
        self._draw_seams()

    def _draw_seams(self) -> None:
        """Each seam as thin lines between its two edges' midpoints, numbered."""
        pattern = self.session.pattern
        segments = []
        for seam in pattern.seams:
            a = pattern.piece(seam.a.piece).edge_points(seam.a.edge, np.array([0.5]))
            b = pattern.piece(seam.b.piece).edge_points(seam.b.edge, np.array([0.5]))
            segments.append([self.board.to_board(seam.a.piece, a)[0], self.board.to_board(seam.b.piece, b)[0]])
        if segments:
            pts = np.array(segments) + [0, 0, 0.004]
            self.seam_handle = self.client.scene.add_line_segments(
                "/board/seams", pts, (150, 150, 220), thickness=1.0, thickness_units="screen"
            )

    def _redraw_strokes(self) -> None:
        scene = self.client.scene
        for handle in getattr(self, "_stroke_handles", []):
            handle.remove()
        self._stroke_handles = []
        s = self.session
        for pair in s.pairs:
            color = pair_color(pair.id)
            on_board = self.board.to_board(pair.pattern.piece, s.pattern_points_on_piece(pair)) + [0, 0, 0.006]
            on_body = pair.body.surface_points + s.surface.normals_at(pair.body.faces) * 0.004
            for name, pts in ((f"/strokes/{pair.id}/pattern", on_board), (f"/strokes/{pair.id}/body", on_body)):
                self._stroke_handles.append(self._polyline(name, pts, color))
            self._stroke_handles.append(
                scene.add_label(f"/strokes/{pair.id}/label", str(pair.id), position=tuple(on_body[0]))
            )
        shown = s.waiting if self.laser.value else s.waiting[-1:]
        for k, stroke in enumerate(shown):
            pts = self.board.to_board(stroke.piece, self._piece_points(stroke)) + [0, 0, 0.006]
            self._stroke_handles.append(self._polyline(f"/strokes/pending{k}", pts, (40, 40, 40)))
        self._status()

    def _piece_points(self, stroke) -> np.ndarray:  # noqa: ANN001 - a PatternStroke in file coordinates
        return self.session.pattern.file_to_piece(stroke.piece, stroke.points)

    def _polyline(self, name: str, pts: np.ndarray, color: tuple[int, int, int]):  # noqa: ANN202
        seg = np.stack([pts[:-1], pts[1:]], axis=1)
        return self.client.scene.add_line_segments(name, seg, color, thickness=4.0, thickness_units="screen")

    # -- drawing ----------------------------------------------------------------------------------------------
    def _ray(self, event) -> tuple[np.ndarray, np.ndarray]:  # noqa: ANN001
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
            hit = self.board.on_board(*self._ray(event))
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
        eye, direction = self._ray(event)
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
        self.drawing.points.append(np.r_[self._ray(event)])
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
            self.laser = gui.add_checkbox(
                "Laser (front and back)", False,
                hint="one stroke across the body lands on its front and its back, for the last two pattern strokes",
            )  # fmt: skip
            self.laser.on_update(lambda _: self._redraw_strokes())
        with gui.add_folder("View"):
            seams = gui.add_checkbox("Show seams", True)
            seams.on_update(lambda _: self._show_seams(seams.value))
            pieces = self.session.pattern.piece_names
            self.flip_choice = gui.add_dropdown("Piece", pieces, initial_value=pieces[0])
            gui.add_button("Turn piece over").on_click(lambda _: self._flip(self.flip_choice.value))
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
            gui.add_button("Unpin all").on_click(lambda _: self._unpin_all())
            gui.add_button("Undo drag").on_click(lambda _: self._drag_history(undo=True))
            gui.add_button("Redo drag").on_click(lambda _: self._drag_history(undo=False))
            self.drag_rate = gui.add_markdown("Wrap first; then press and drag on the garment.")
        with gui.add_folder("Files"):
            gui.add_upload_button("Open body (OBJ, GLB, PLY)").on_upload(self._upload_body)
            gui.add_upload_button("Open pattern (JSON, SVG)").on_upload(self._upload_pattern)
            gui.add_upload_button("Open strokes (JSON)").on_upload(self._upload_strokes)
            gui.add_button("Save strokes").on_click(lambda _: self._download_strokes())
            gui.add_button("Save garment (GLB, OBJ, report)").on_click(lambda _: self._download_garment())

    def _unpin_all(self) -> None:
        if getattr(self, "dragging", None) is not None and not self.dragger.busy:
            self.drag_undo.append(self.dragging.snapshot())
            self.dragging.unpin(all=True)
            self._show_pins()

    def _show_seams(self, on: bool) -> None:
        if getattr(self, "seam_handle", None) is not None:
            self.seam_handle.visible = on

    def _flip(self, piece: str) -> None:
        """Turn a piece over (its back becomes its outside): a new pattern, so a new session."""
        pattern = self.session.pattern.copy()
        k = pattern.piece_index(piece)
        pattern.pieces[k].flipped = not pattern.pieces[k].flipped
        self._replace(pattern=pattern)

    def _status(self, extra: str = "") -> None:
        s = self.session
        lines = [f"**{s.pattern.name}** on the body: {len(s.pairs)} stroke pair(s)."]
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

    def _edit(self, action) -> None:  # noqa: ANN001
        try:
            action()
        except InputError as e:
            self.notify("Could not do that", e.message, "red")
        self._redraw_strokes()

    def notify(self, title: str, body: str, color: str | None = None) -> None:
        self.client.add_notification(title, body, color=color, auto_close_seconds=8.0)

    # -- wrap -------------------------------------------------------------------------------------------------
    def _start_wrap(self) -> None:
        if self.busy:
            return
        strokes = self.session.strokes()
        if not len(strokes):
            self.notify("No strokes yet", "Draw at least one stroke pair (pattern, then body) to wrap.", "yellow")
            return
        self.busy = True
        self.cancel.clear()
        self.wrap_button.disabled = True
        self.cancel_button.disabled = False
        threading.Thread(target=self._wrap, args=(strokes,), daemon=True, name="kitsuke-app-wrap").start()

    def _wrap(self, strokes) -> None:  # noqa: ANN001
        from dataclasses import replace

        from ..dressing import target_misses

        s = self.session
        note = self.client.add_notification("Wrapping", "0 s", loading=True, with_close_button=False)
        done = threading.Event()

        def tick() -> None:  # the elapsed time, so that a long wrap is seen to be working
            t0 = time.monotonic()
            while not done.wait(0.5):
                note.body = f"{time.monotonic() - t0:.0f} s (Cancel wrap stops it)"

        threading.Thread(target=tick, daemon=True).start()
        try:
            params = replace(self.app.options, edge_length=float(self.edge.value)).wrap_params(s.body, s.pattern)
            garment = self.app.worker.wrap(s.body, s.pattern, strokes, params, cancel=self.cancel)
        except Cancelled:
            self._wrap_ended(note, done, "Wrap cancelled", "Nothing changed.", "yellow")
            return
        except (InputError, ComputationError) as e:
            reason = e.message if isinstance(e, InputError) else f"{e.stage}: {e.message}"
            self._wrap_ended(note, done, "The wrap failed", reason, "red")
            return
        s.garment = garment
        self._start_drag(garment)
        misses = target_misses(garment)
        verdict = "all quality targets met" if not misses else "missed: " + "; ".join(misses)
        summary = f"Dressed: {garment.n_vertices} vertices, {garment.timings.get('wrap', 0.0):.1f} s; {verdict}."
        self._wrap_ended(note, done, "Dressed", summary, "green" if not misses else "yellow")
        self._status(summary)

    # -- drag and pins ----------------------------------------------------------------------------------------
    def _start_drag(self, garment) -> None:  # noqa: ANN001 - a DressedGarment
        from ..dressing import DragSession

        self.dragging = DragSession(self.session.body, garment)
        self.drag_undo: list = []
        self.drag_redo: list = []
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
        if event.phase == "start":
            self.dragger.submit("grab", np.asarray(event.start_position, dtype=np.float64))
        elif event.phase == "update":
            self.dragger.submit("move", self._body_target(event))
        else:
            self.dragger.submit("release", None)

    def _body_target(self, event) -> np.ndarray:  # noqa: ANN001
        """Where the pointer is on the body (its ray's first hit), or the body point nearest the pointer's place
        on the camera-facing plane when the ray misses the body."""
        eye, direction = self._ray(event)
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
        v = int(d.model.faces[hit.faces[0]][np.argmax(hit.barycentric[0])])
        self.drag_undo.append(d.snapshot())
        self.drag_redo.clear()
        if d.pinned[v]:
            d.unpin(vertices=[v])
        else:
            d.pin(vertices=[v])
        self._show_pins()

    def _drag_history(self, undo: bool) -> None:
        if getattr(self, "dragging", None) is None or self.dragger.busy:
            return
        src, dst = (self.drag_undo, self.drag_redo) if undo else (self.drag_redo, self.drag_undo)
        if not src:
            return
        dst.append(self.dragging.snapshot())
        self.dragging.restore(src.pop())
        self.push_positions()
        self._show_pins()

    def _wrap_ended(self, note, done: threading.Event, title: str, body: str, color: str) -> None:  # noqa: ANN001
        done.set()
        note.remove()
        self.notify(title, body, color)
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

    def _upload_body(self, event) -> None:  # noqa: ANN001
        from ..body import load_body

        path = self._received(event, BODY_SUFFIXES)
        if path is None:
            return
        try:
            body = load_body(path)
        except InputError as e:
            self.notify("Not a body this app can use", f"{event.target.value.name}: {e.message}", "red")
            return
        self._replace(body=body)

    def _upload_pattern(self, event) -> None:  # noqa: ANN001
        from ..pattern import load_pattern

        path = self._received(event, PATTERN_SUFFIXES)
        if path is None:
            return
        try:
            pattern = load_pattern(path)
        except InputError as e:
            self.notify("Not a pattern this app can use", f"{event.target.value.name}: {e.message}", "red")
            return
        self._replace(pattern=pattern)

    def _upload_strokes(self, event) -> None:  # noqa: ANN001
        from ..dressing import read_strokes

        path = self._received(event, (".json",))
        if path is None:
            return
        try:
            self.session.load_strokes(read_strokes(path))
        except InputError as e:
            self.notify("Strokes not loaded", f"{event.target.value.name}: {e.message}", "red")
            return
        self._redraw_strokes()

    def _replace(self, *, body=None, pattern=None) -> None:  # noqa: ANN001
        """A new body or pattern: a fresh session (strokes belong to the old ones), the scene rebuilt."""
        s = self.session
        self.session = DressingSession(body or s.body, pattern or s.pattern)
        self.board = BoardLayout.of(self.session.pattern)
        self.client.scene.reset()
        self._build_scene()
        self._redraw_strokes()

    def _download_strokes(self) -> None:
        from ..dressing import strokes_to_json

        self.client.send_file_download(
            "strokes.json", strokes_to_json(self.session.strokes()).encode(), save_immediately=True
        )

    def _download_garment(self) -> None:
        """The garment as it is now (dragged, pinned) with its quality report."""
        from .._files import write_json_atomic
        from ..dressing.export import write_garment_glb, write_garment_obj

        if getattr(self, "dragging", None) is None:
            self.notify("Nothing dressed yet", "Wrap first, then save the garment.", "yellow")
            return
        garment, body = self.dragging.garment(), self.session.body.mesh
        with tempfile.TemporaryDirectory() as d:
            paths = [Path(d) / n for n in ("garment.glb", "garment.obj", "garment_report.json")]
            write_garment_glb(garment, paths[0], body=body)
            write_garment_obj(garment, paths[1])
            write_json_atomic(paths[2], self.dragging.report().to_dict())
            for p in paths:
                self.client.send_file_download(p.name, p.read_bytes(), save_immediately=True)


class Dragger:
    """Runs a tab's drag in its own thread, newest pointer position first: a move waiting when a newer one comes
    is dropped, so the garment follows the pointer instead of replaying its path late. Grab and release are
    never dropped. Measures the updates per second it manages."""

    def __init__(self, view: ClientView) -> None:
        self.view = view
        self._ops: list[tuple[str, np.ndarray | None]] = []
        self._cv = threading.Condition()
        self.busy = False
        self.update_s: list[float] = []
        threading.Thread(target=self._run, daemon=True, name="kitsuke-app-drag").start()

    def submit(self, op: str, point: np.ndarray | None) -> None:
        with self._cv:
            if op == "move" and self._ops and self._ops[-1][0] == "move":
                self._ops[-1] = (op, point)
            else:
                self._ops.append((op, point))
            self._cv.notify()

    def _run(self) -> None:
        while True:
            with self._cv:
                while not self._ops:
                    self._cv.wait()
                op, point = self._ops.pop(0)
            try:
                self._do(op, point)
            except InputError as e:  # a grab on a pinned point, a drag off the garment: said, not fatal
                self.view.notify("Drag", e.message, "yellow")
                self._abandon()
            except ComputationError as e:  # the drag could not be solved: back to before it
                self.view.notify("The drag failed", f"{e.stage}: {e.message}", "red")
                self._abandon()

    def _abandon(self) -> None:
        v = self.view
        if v.dragging.grabbed is not None and v.drag_undo:
            v.dragging.restore(v.drag_undo.pop())
            v.dragging.grabbed = None
            v.push_positions()
        with self._cv:
            self._ops = [op for op in self._ops if op[0] == "grab"]  # the rest belonged to the failed drag
        self.busy = False

    def _do(self, op: str, point: np.ndarray | None) -> None:
        v, d = self.view, self.view.dragging
        if op == "grab":
            v.drag_undo.append(d.snapshot())
            v.drag_redo.clear()
            d.grab(point)
            self.busy = True
            self._t_grab = time.perf_counter()
            self.update_s.clear()
        elif op == "move" and d.grabbed is not None:
            t0 = time.perf_counter()
            d.move_to(point)
            v.push_positions()
            self._t_last = time.perf_counter()
            self.update_s.append(self._t_last - t0)
        elif op == "release" and d.grabbed is not None:
            note = v.client.add_notification("Settling", "the cloth after the drag", loading=True)
            try:
                d.release()
            finally:
                note.remove()
            v.push_positions()
            self.busy = False
            n = len(self.update_s)
            if n:
                rate = n / max(self._t_last - self._t_grab, 1e-9)  # while dragging (the release apart)
                v.drag_rate.content = (
                    f"Last drag: {n} updates, {1e3 * float(np.median(self.update_s)):.0f} ms each, "
                    f"{rate:.1f} per second."
                )


class App:
    """The app: a viser server, one `ClientView` per browser tab, one wrap worker shared by the tabs (their
    wraps run in turn)."""

    def __init__(self, body=None, pattern=None, strokes=None, options=None) -> None:  # noqa: ANN001
        from ..body import default_body
        from ..dressing.options import DressOptions
        from ..pattern import default_kimono

        self.options = options or DressOptions()  # the wrap's defaults, as `kitsuke dress` has them
        self.body = default_body() if body is None else body
        self.pattern = default_kimono() if pattern is None else pattern
        self.strokes = strokes
        self.views: dict[int, ClientView] = {}
        self.server = None
        self.worker: WrapWorker | None = None
        self.uploads = tempfile.TemporaryDirectory(prefix="kitsuke-app-")

    def start(self, host: str = "127.0.0.1", port: int = 8080) -> str:
        """Listen on host:port (the next free port if it is taken); returns the URL."""
        import viser

        self.worker = WrapWorker()
        self.server = viser.ViserServer(host=host, port=port, label="kitsuke", verbose=False)
        self.server.gui.configure_theme(show_share_button=False, titlebar_content=None)  # nothing goes online
        self.server.scene.set_up_direction("+y")  # kitsuke's bodies stand on Y
        cam = self.server.initial_camera
        cam.up_direction = (0.0, 1.0, 0.0)
        cam.fov = np.radians(40.0)
        cam.position = (0.75, 1.0, 3.6)
        cam.look_at = (0.75, 0.95, 0.0)
        self.server.on_client_connect(self._connect)
        self.server.on_client_disconnect(lambda client: self.views.pop(client.client_id, None))
        return self.url

    @property
    def url(self) -> str:
        host = self.server.get_host()
        return f"http://{'127.0.0.1' if host in ('0.0.0.0', '') else host}:{self.server.get_port()}"

    def _connect(self, client) -> None:  # noqa: ANN001
        self.views[client.client_id] = ClientView(self, client)

    def stop(self) -> None:
        if self.server is not None:
            self.server.stop()
        if self.worker is not None:
            self.worker.close()
        self.uploads.cleanup()


def free_port() -> int:
    import socket

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def serve(app: App, host: str, port: int, *, open_browser: bool = True) -> None:
    """Run until Ctrl-C, printing the URL (and opening it in a browser where there is a display)."""
    url = app.start(host, port)
    print(f"kitsuke app: {url}  (Ctrl-C stops it)", flush=True)
    if open_browser and (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY") or os.name == "nt"):
        import webbrowser

        webbrowser.open(url)
    try:
        while True:
            time.sleep(1.0)
    except KeyboardInterrupt:
        pass
    finally:
        app.stop()
