"""The browser app (`kitsuke app`): draw stroke pairs on the pattern and the body, wrap, and save, in a local web
page (viser). Thin over the library: `DressingSession` holds one user's dressing, `App` serves the pages."""

from .board import BoardLayout
from .server import App, free_port, serve
from .session import DressingSession, pair_color
from .worker import Cancelled, WrapWorker

__all__ = ["App", "BoardLayout", "Cancelled", "DressingSession", "WrapWorker", "free_port", "pair_color", "serve"]
