"""Wraps run in a child process: the app's server stays responsive while one runs, Cancel stops it at once (the
process is ended and a fresh one started), and nothing a wrap does can take the app down with it.

worker = WrapWorker()
garment = worker.wrap(body, pattern, strokes, params, cancel=threading.Event())   # DressedGarment
worker.close()
"""

from __future__ import annotations

import multiprocessing as mp
import threading
import time
from collections.abc import Callable

from ..errors import ComputationError, InputError


class Cancelled(Exception):
    """The wrap was cancelled."""


def _serve(conn) -> None:  # noqa: ANN001 - a multiprocessing Connection
    """The child: take ("wrap", body, pattern, strokes, params) or ("rewrap", body, garment, strokes, pins) jobs,
    say ("stage", name) as a wrap goes, and answer ("ok", result) or the error."""
    import signal

    from ..dressing import wrap
    from ..dressing.rewrap import rewrap

    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C in the terminal is for the app, which ends this process

    while True:
        try:
            job = conn.recv()
        except EOFError:
            return
        kind, body, garment, strokes, extra = job
        try:
            if kind == "wrap":
                result = wrap(body, garment, strokes, params=extra, progress=lambda s: conn.send(("stage", s)))
            else:
                result = rewrap(body, garment, strokes, pins=extra).garment
            conn.send(("ok", result))
        except InputError as e:
            conn.send(("input", e.message, e.path))
        except ComputationError as e:
            conn.send(("computation", e.stage, e.message))
        except Exception as e:  # noqa: BLE001 - reported to the user as one line, the app carries on
            conn.send(("error", f"{type(e).__name__}: {e}", None))


class WrapWorker:
    """A child process that wraps, one job at a time (a lock keeps concurrent callers in turn)."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._proc: mp.process.BaseProcess | None = None
        self._start()

    def _start(self) -> None:
        ctx = mp.get_context("spawn")  # a fresh interpreter: no threads or viser state copied into it
        self._conn, child = ctx.Pipe()
        self._proc = ctx.Process(target=_serve, args=(child,), name="kitsuke-wrap", daemon=True)
        self._proc.start()
        child.close()

    def _restart(self) -> None:
        if self._proc is not None and self._proc.is_alive():
            self._proc.terminate()
            self._proc.join(timeout=5)
        self._start()

    def wrap(
        self,
        body,
        pattern,
        strokes,
        params,
        *,
        cancel: threading.Event | None = None,
        timeout_s: float = 600,
        progress: Callable[[str], None] | None = None,
    ):  # noqa: ANN001, ANN201
        """The garment of `kitsuke.dressing.wrap(body, pattern, strokes, params=params)`, computed in the child;
        `progress(stage)` hears each stage as it starts.

        Raises what wrap raises (InputError, ComputationError), Cancelled when `cancel` is set, and
        ComputationError ("wrap") when the child dies or the wrap takes longer than `timeout_s`."""
        return self._run(("wrap", body, pattern, strokes, params), cancel, timeout_s, progress)

    def rewrap(self, body, garment, strokes, pins, *, cancel: threading.Event | None = None, timeout_s: float = 600):  # noqa: ANN001, ANN201
        """The garment (a GarmentFile) of `kitsuke.dressing.rewrap.rewrap(body, garment, strokes, pins=pins)`,
        computed in the child; raises as `wrap` does."""
        return self._run(("rewrap", body, garment, strokes, pins), cancel, timeout_s)

    def _run(self, job: tuple, cancel: threading.Event | None, timeout_s: float, progress=None):  # noqa: ANN001, ANN202
        with self._lock:
            if self._proc is None or not self._proc.is_alive():
                self._start()
            self._conn.send(job)
            t0 = time.monotonic()
            while True:
                while not self._conn.poll(0.1):
                    if cancel is not None and cancel.is_set():
                        self._restart()
                        raise Cancelled()
                    if not self._proc.is_alive():
                        self._start()
                        raise ComputationError("wrap", "the wrap's process died (out of memory?)")
                    if time.monotonic() - t0 > timeout_s:
                        self._restart()
                        raise ComputationError("wrap", f"the wrap took longer than {timeout_s:.0f} s and was stopped")
                answer = self._conn.recv()
                if answer[0] != "stage":
                    break
                if progress is not None:
                    progress(answer[1])
        kind = answer[0]
        if kind == "ok":
            return answer[1]
        if kind == "input":
            raise InputError(answer[1], answer[2])
        if kind == "computation":
            raise ComputationError(answer[1], answer[2])
        raise ComputationError("wrap", answer[1])

    def close(self) -> None:
        if self._proc is not None and self._proc.is_alive():
            self._conn.close()
            self._proc.join(timeout=2)
            if self._proc.is_alive():
                self._proc.terminate()
        self._proc = None
