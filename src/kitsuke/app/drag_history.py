"""The drags made on one dressed garment in the app: pins, grabs and moves, each operation undoable, and all of
them recorded as a kitsuke drags file (SPEC §3.5) that `kitsuke drag GARMENT --drags FILE` replays.

history = DragHistory(DragSession(body, garment))
history.toggle_pin(vertex); history.grab(point); history.move(target); history.release()
history.undo(); history.redo()
write_drags(history.drags(), "drags.json")
"""

from __future__ import annotations

import numpy as np

from ..dressing import DragSession
from ..dressing.drags import Drags, DragStep


class DragHistory:
    """A `DragSession` with undo and redo per operation (a pin, an unpin, a whole drag) and its operations
    recorded as drags-file steps. `steps` : the operations so far, in order."""

    def __init__(self, session: DragSession) -> None:
        self.session = session
        self.steps: list[DragStep] = []
        self._undo: list[tuple[object, list[DragStep]]] = []  # (snapshot, steps) before each operation
        self._redo: list[tuple[object, list[DragStep]]] = []
        self._grab: np.ndarray | None = None
        self._path: list[np.ndarray] = []

    def _mark(self) -> None:
        self._undo.append((self.session.snapshot(), list(self.steps)))
        self._redo.clear()

    # -- pins -------------------------------------------------------------------------------------------------
    def toggle_pin(self, vertex: int) -> bool:
        """Pin a garment vertex, or unpin it if pinned. Returns whether it is pinned now."""
        d = self.session
        self._mark()
        at = d.positions[vertex].copy()[None]
        if d.pinned[vertex]:
            d.unpin(vertices=[vertex])
            self.steps.append(DragStep(unpin=at))
            return False
        d.pin(vertices=[vertex])
        self.steps.append(DragStep(pins=at))
        return True

    def unpin_all(self) -> None:
        self._mark()
        self.session.unpin(all=True)
        self.steps.append(DragStep(unpin="all"))

    # -- a drag -----------------------------------------------------------------------------------------------
    def grab(self, point: np.ndarray) -> None:
        """Mouse down on the garment at `point` (3,) metres. InputError (nothing changed): a pinned point."""
        self._mark()
        try:
            self.session.grab(point)
        except Exception:
            self._undo.pop()
            raise
        self._grab, self._path = np.asarray(point, dtype=np.float64), []

    def move(self, target: np.ndarray) -> None:
        """The grabbed point towards `target` (3,) metres on the body surface."""
        self.session.move_to(target)
        self._path.append(np.asarray(target, dtype=np.float64))

    def release(self) -> None:
        """Mouse up: the cloth settles, and the drag becomes one step."""
        self.session.release()
        if self._grab is not None:
            self.steps.append(DragStep(grab=self._grab, path=np.array(self._path).reshape(-1, 3)))
        self._grab = None

    def abandon(self) -> None:
        """A drag that failed half-way: the garment as it was before the grab, and no step recorded."""
        if self.session.grabbed is not None and self._undo:
            snapshot, self.steps = self._undo.pop()
            self.session.restore(snapshot)
            self.session.grabbed = None
        self._grab = None

    # -- undo -------------------------------------------------------------------------------------------------
    def undo(self) -> bool:
        return self._step(self._undo, self._redo)

    def redo(self) -> bool:
        return self._step(self._redo, self._undo)

    def _step(self, src: list, dst: list) -> bool:
        if not src or self.session.grabbed is not None:
            return False
        dst.append((self.session.snapshot(), list(self.steps)))
        snapshot, self.steps = src.pop()
        self.session.restore(snapshot)
        return True

    def drags(self) -> Drags:
        """The operations so far as a drags file."""
        return Drags(list(self.steps), {"made_with": "kitsuke app"})
