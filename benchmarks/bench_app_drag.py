"""Benchmark of dragging a garment in the browser app: updates per second and their time, over a real browser.

Run: `python benchmarks/bench_app_drag.py [--edge-cm 2.5] [--seconds 4]` (needs Debian's chromium and playwright).
Target (the app issue): at least 20 updates per second for a 5,000-vertex garment, measured in the browser's round
trip.

The default kimono is dressed at `--edge-cm` (2.5 cm: about 6,000 vertices) with its packaged strokes, then the app
is opened in headless Chromium and the mouse drags the kimono's front up and down for `--seconds`, moving every
16 ms (60 Hz). Measured: the drag events viser delivered, the updates the server computed and sent (each a
`DragSession.move_to` and the garment's vertices sent to the browser; a newer pointer position replaces one not
yet computed), their time, and the release's. The browser shows each update when it arrives; its frame time
under software WebGL is not included. Then the server alone: pointer positions submitted at 60 Hz from Python
(as a browser that keeps up would send them), each update computed and sent to the open tab.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import shutil
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests"))


def _bytes(frame) -> bytes:  # noqa: ANN001 - a websocket frame's payload (bytes or str)
    return frame if isinstance(frame, bytes) else frame.encode()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--edge-cm", type=float, default=2.5)
    ap.add_argument("--seconds", type=float, default=4.0)
    args = ap.parse_args()
    from playwright.sync_api import sync_playwright

    from app.conftest import FLAGS, VIEWPORT, AppPage
    from kitsuke.app import App, free_port
    from kitsuke.dressing import load_packaged_strokes
    from kitsuke.dressing.kimono import dress_default_kimono
    from kitsuke.dressing.wrap import WrapParams
    from kitsuke.geometry import TriMesh
    from kitsuke.geometry.surface import Surface

    app = App(strokes=load_packaged_strokes("kimono_default"))
    app.start("127.0.0.1", free_port())
    garment = dress_default_kimono(app.body, params=WrapParams(edge_length_cm=args.edge_cm))
    with sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=shutil.which("chromium"), args=FLAGS)
        page = browser.new_page(viewport=VIEWPORT)
        # the round trip, seen from the page: each drag message it sends, and each garment update it receives
        # (the largest frames: the vertices); an update answers the last drag message sent before it
        sent: list[float] = []
        received: list[float] = []

        def on_ws(ws) -> None:  # noqa: ANN001
            ws.on("framesent", lambda f: sent.append(time.perf_counter()) if b"Drag" in _bytes(f) else None)
            ws.on("framereceived", lambda f: received.append(time.perf_counter()) if len(_bytes(f)) > 40_000 else None)

        page.on("websocket", on_ws)
        ap_ = AppPage(app, page)
        page.goto(app.url)
        ap_.wait_connected()
        view = ap_.view
        view._start_drag(garment)
        page.wait_for_timeout(1500)
        d = view.dragging
        events = []
        submit = view.dragger.submit

        def counting(op, point) -> None:  # noqa: ANN001 - every drag event the browser delivered
            events.append(time.perf_counter())
            submit(op, point)

        view.dragger.submit = counting
        hit = Surface(TriMesh(d.positions, d.model.faces)).cast(np.array([[0.12, 0.6, 2.0]]), np.array([[0, 0, -1.0]]))
        start = hit.points[0]
        px0 = ap_.screen(start[None])[0]
        px1 = ap_.screen((start + [0, 0.15, 0])[None])[0]
        m = page.mouse
        m.move(*px0)
        m.down()
        t0 = time.perf_counter()
        k = 0
        while time.perf_counter() - t0 < args.seconds:
            s = 0.5 - 0.5 * np.cos(2 * np.pi * k / 120)  # up and down every 2 s
            p = px0 + (px1 - px0) * s
            m.move(float(p[0]), float(p[1]))
            k += 1
            page.wait_for_timeout(16)
        drag_s = time.perf_counter() - t0
        m.up()
        in_drag = [r for r in received if t0 <= r <= t0 + drag_s]
        trips = [r - max(x for x in sent if x < r) for r in in_drag if any(x < r for x in sent)]
        t_up = time.perf_counter()
        while view.dragger.busy or view.dragger._ops:
            time.sleep(0.05)
        release_s = time.perf_counter() - t_up
        upd = np.array(view.dragger.update_s)
        # the server alone: pointer positions submitted at 60 Hz from here (as the browser would on a machine that
        # keeps up), each update computed and sent to the connected tab
        view.dragger.submit = submit
        body_pts = Surface(view.session.body.mesh)
        start = body_pts.closest((d.positions[d.vertices_at(start[None])[0]])[None]).points[0]
        submit("grab", start)
        t1 = time.perf_counter()
        k = 0
        while time.perf_counter() - t1 < args.seconds:
            s = 0.5 - 0.5 * np.cos(2 * np.pi * k / 120)
            submit("move", body_pts.closest((start + [0, 0.12 * s, 0])[None]).points[0])
            k += 1
            time.sleep(1 / 60)
        server_s = time.perf_counter() - t1
        while view.dragger._ops and view.dragger._ops[0][0] == "move":
            time.sleep(0.01)
        server_upd = np.array(view.dragger.update_s)
        submit("release", None)
        while view.dragger.busy or view.dragger._ops:
            time.sleep(0.05)
        out = {
            "garment_vertices": int(len(garment.positions)),
            "mouse_moves": k,
            "drag_seconds": round(drag_s, 2),
            "drag_events_from_browser_per_s": round(len(events) / drag_s, 1),
            "updates_sent": int(len(upd)),
            "updates_per_s": round(len(upd) / drag_s, 1),
            "update_ms_median": round(float(np.median(upd)) * 1e3, 1),
            "update_ms_p95": round(float(np.percentile(upd, 95)) * 1e3, 1),
            "release_s": round(release_s, 2),
            "browser_drag_messages_sent_per_s": round(sum(t0 <= x <= t0 + drag_s for x in sent) / drag_s, 1),
            "browser_updates_received_per_s": round(len(in_drag) / drag_s, 1),
            "browser_round_trip_ms_median": round(1e3 * float(np.median(trips)), 0) if trips else None,
            "server_alone_updates_per_s": round(len(server_upd) / server_s, 1),
            "server_alone_update_ms_median": round(float(np.median(server_upd)) * 1e3, 1),
            "machine": {"cores": os.cpu_count(), "processor": platform.processor(), "load": os.getloadavg()},
        }
        print(json.dumps(out, indent=1))
        browser.close()
    app.stop()


if __name__ == "__main__":
    main()
