"""`LocalRunner`: the batch's workers as processes on this machine, no Ray needed (`kitsuke batch --local`)."""

from __future__ import annotations

import os
import pickle
import queue
import signal
import socket
import subprocess
import sys
import threading
from collections.abc import Hashable
from multiprocessing.connection import Connection
from multiprocessing.connection import wait as wait_connections
from typing import Any

from .outcome import JobKind
from .runners import Runner, SharedInputs, Task, WorkerSlot
from .workers import WorkerCore


class LocalRunner(Runner):
    """Workers are processes on this machine: fresh interpreters (`python -m kitsuke.batch._worker`, so nothing of
    the driver's state or its main script is inherited), each talking to the driver over a socket pair.
    log_dir: where each worker's stdout and stderr go (worker-N.log), or None to discard them."""

    name = "a process pool on this machine"

    def __init__(self, *, log_dir: str | os.PathLike[str] | None = None, **kwargs: Any):
        super().__init__(**kwargs)
        self.log_dir = log_dir

    def use_log_dir(self, path: str | os.PathLike[str]) -> None:
        if self.log_dir is None:
            os.makedirs(path, exist_ok=True)
            self.log_dir = path

    def _open(self, kind: JobKind) -> int:
        return self.workers or os.cpu_count() or 1

    def _start(self, slot: WorkerSlot, kind: JobKind) -> None:
        here, there = socket.socketpair()
        log = subprocess.DEVNULL
        if self.log_dir is not None:
            log = open(os.path.join(os.fspath(self.log_dir), f"worker-{slot.id}.log"), "ab")
        try:
            process = subprocess.Popen(
                [sys.executable, "-m", "kitsuke.batch._worker", str(there.fileno())],
                pass_fds=[there.fileno()],
                # The driver's import path, so that a JobKind defined beside the driver's script unpickles here.
                env={**os.environ, "PYTHONPATH": os.pathsep.join(p for p in sys.path if p)},
                stdin=subprocess.DEVNULL,
                stdout=log,
                stderr=log,
                # Its own session: a Ctrl-C at the terminal stops the driver, which stops its workers; a worker
                # never dies of it half-way through writing its answer.
                start_new_session=True,
            )
        finally:
            there.close()
            if log is not subprocess.DEVNULL:
                log.close()
        conn = Connection(here.detach())
        slot.handle = (process, conn)
        try:
            conn.send(kind)
        except OSError:
            pass  # it died at once: _poll reports it

    def _send(self, slot: WorkerSlot, task: Task, inputs: SharedInputs) -> None:
        keys = list((task.keys or {}).values())
        missing: dict[Hashable, bytes] = {}
        slot.model.admit(keys, lambda k: missing.setdefault(k, inputs.pickled(k)))
        try:
            slot.handle[1].send((task.job, task.keys, missing))
        except OSError:
            pass  # the worker is dead: _poll reports it and the task goes back to the queue

    def _poll(self, slots: list[WorkerSlot], timeout: float) -> list[tuple[WorkerSlot, str, Any]]:
        by_conn = {s.handle[1]: s for s in slots}
        news = []
        for conn in wait_connections(list(by_conn), timeout):
            slot = by_conn[conn]
            try:
                while conn.poll():
                    news.append((slot, *conn.recv()))
            except (EOFError, OSError):  # the worker's end closed: it exited
                news.append((slot, "dead", _exit_reason(slot.handle[0])))
        return news

    def _stop(self, slot: WorkerSlot) -> None:
        process, conn = slot.handle
        if process.poll() is None:
            process.kill()
        process.wait()
        conn.close()

    def _close(self, slots: list[WorkerSlot]) -> None:
        for slot in slots:
            self._stop(slot)


def _exit_reason(process: subprocess.Popen) -> str:
    try:
        code = process.wait(5)
    except subprocess.TimeoutExpired:
        return "it closed its connection"
    if code < 0:
        return f"killed by {signal.Signals(-code).name}"
    return f"exit code {code}"


def local_worker(fd: int) -> None:
    """A local worker process (`kitsuke.batch._worker`): receive the job kind, warm, say ready, then run each job
    sent until the connection closes. A reader thread takes messages off the socket as they come, so the driver
    never blocks sending the next job, and the worker exits at once when the driver is gone (killed: nothing else
    would stop it)."""
    conn = Connection(fd)
    core = WorkerCore(conn.recv())
    try:
        conn.send(("ready", core.warm()))
    except Exception as e:  # noqa: BLE001 - reported to the driver, which counts failed warm-ups
        conn.send(("dead", f"its warm-up failed: {type(e).__name__}: {e}"))
        return
    inbox: queue.Queue = queue.Queue()

    def read() -> None:
        while True:
            try:
                inbox.put(conn.recv())
            except (EOFError, OSError):
                os._exit(0)

    threading.Thread(target=read, daemon=True).start()
    while True:
        job, keys, sent = inbox.get()
        outcome = core.run(job, keys, lambda k, sent=sent: pickle.loads(sent[k]))
        conn.send(("done", outcome))
