"""The browser app (`kitsuke app`): draw stroke pairs on the pattern and the body, edit the pattern, wrap, pin,
drag and save, in a local web page (viser). Thin over the library: `DressingSession` holds one user's strokes,
`PatternEditor` their pattern edits, `DragHistory` their drags; `App` serves the pages."""

from .board import BoardLayout
from .drag_history import DragHistory
from .editor import PatternEditor
from .server import App, free_port, serve
from .session import DressingSession, pair_color
from .worker import Cancelled, WrapWorker

__all__ = [
    "App",
    "BoardLayout",
    "Cancelled",
    "DragHistory",
    "DressingSession",
    "PatternEditor",
    "WrapWorker",
    "free_port",
    "pair_color",
    "serve",
]
