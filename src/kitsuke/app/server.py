"""The browser app on viser: one `ClientView` per browser tab (`kitsuke.app.view`), one wrap worker shared by
the tabs.

app = App(body, pattern)                 # not yet listening
app.start(host="127.0.0.1", port=8080)   # the URL: app.url
"""

from __future__ import annotations

import os
import tempfile
import threading
import time

import numpy as np

from .view import ClientView
from .worker import WrapWorker


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
        self._worker: WrapWorker | None = None
        self._worker_lock = threading.Lock()
        self.uploads = tempfile.TemporaryDirectory(prefix="kitsuke-app-")

    def start(self, host: str = "127.0.0.1", port: int = 8080) -> str:
        """Listen on host:port (the next free port if it is taken); returns the URL."""
        import viser

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
    def worker(self) -> WrapWorker:
        """The wrap worker, started at the first wrap (a tab that never wraps costs no process)."""
        with self._worker_lock:
            if self._worker is None:
                self._worker = WrapWorker()
            return self._worker

    @property
    def url(self) -> str:
        host = self.server.get_host()
        return f"http://{'127.0.0.1' if host in ('0.0.0.0', '') else host}:{self.server.get_port()}"

    def _connect(self, client) -> None:  # noqa: ANN001
        self.views[client.client_id] = ClientView(self, client)

    def stop(self) -> None:
        if self.server is not None:
            self.server.stop()
        if self._worker is not None:
            self._worker.close()
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
