"""A tab's garment drag, run in its own thread: the newest pointer position first."""

from __future__ import annotations

import threading
import time
from typing import TYPE_CHECKING

import numpy as np

from ..errors import ComputationError, InputError

if TYPE_CHECKING:
    from .view import ClientView


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
        if v.dragging.grabbed is not None:
            v.drag_history.abandon()
            v.push_positions()
        with self._cv:
            self._ops = [op for op in self._ops if op[0] == "grab"]  # the rest belonged to the failed drag
        self.busy = False

    def _do(self, op: str, point: np.ndarray | None) -> None:
        v, d, history = self.view, self.view.dragging, self.view.drag_history
        if op == "grab":
            history.grab(point)
            self.busy = True
            v.show_strain()  # the plain garment while it moves
            self._t_grab = time.perf_counter()
            self.update_s.clear()
        elif op == "move" and d.grabbed is not None:
            t0 = time.perf_counter()
            history.move(point)
            v.push_positions()
            self._t_last = time.perf_counter()
            self.update_s.append(self._t_last - t0)
        elif op == "release" and d.grabbed is not None:
            note = v.client.add_notification("Settling", "the cloth after the drag", loading=True)
            try:
                history.release()
            finally:
                note.remove()
            v.push_positions()
            self.busy = False
            v.show_strain()
            n = len(self.update_s)
            if n:
                rate = n / max(self._t_last - self._t_grab, 1e-9)  # while dragging (the release apart)
                v.drag_rate.content = (
                    f"Last drag: {n} updates, {1e3 * float(np.median(self.update_s)):.0f} ms each, "
                    f"{rate:.1f} per second."
                )
