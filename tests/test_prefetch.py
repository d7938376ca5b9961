"""kitsuke._prefetch: items in order, errors where they happen, and an early stop that ends the thread."""

from __future__ import annotations

import threading
import time

import pytest

from kitsuke._prefetch import prefetch


def test_items_in_order_and_ahead():
    produced = []

    def items():
        for i in range(50):
            produced.append(i)
            yield i

    it = prefetch(items(), depth=4)
    assert next(it) == 0
    time.sleep(0.05)
    assert 2 <= len(produced) <= 7  # ran ahead, but no further than the queue allows
    assert [0, *it] == list(range(50))


def test_error_is_raised_at_its_item():
    def items():
        yield 1
        yield 2
        raise ValueError("frame 3 is corrupt")

    it = prefetch(items())
    assert next(it) == 1 and next(it) == 2
    with pytest.raises(ValueError, match="frame 3"):
        next(it)


def test_closing_early_stops_the_thread():
    def endless():
        i = 0
        while True:
            yield i
            i += 1

    before = threading.active_count()
    it = prefetch(endless(), depth=2)
    assert next(it) == 0
    it.close()
    deadline = time.monotonic() + 2
    while threading.active_count() > before and time.monotonic() < deadline:
        time.sleep(0.01)
    assert threading.active_count() == before
