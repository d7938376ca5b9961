"""Progress bars that show on a terminal and stay quiet otherwise (SPEC §2)."""

from __future__ import annotations

import sys
from collections.abc import Iterable, Iterator
from typing import TypeVar

T = TypeVar("T")


def progress(
    items: Iterable[T], *, total: int | None = None, desc: str = "", enabled: bool | None = None
) -> Iterator[T]:
    """Iterate `items` with a tqdm bar on stderr when stderr is a terminal (or when `enabled` is True)."""
    show = sys.stderr.isatty() if enabled is None else enabled
    if not show:
        yield from items
        return
    from tqdm import tqdm

    yield from tqdm(items, total=total, desc=desc, unit="it", leave=False, dynamic_ncols=True)
