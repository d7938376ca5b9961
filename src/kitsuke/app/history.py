"""Undo and redo over immutable states: the app's strokes and its pattern edits both keep one."""

from __future__ import annotations

from typing import Generic, TypeVar

T = TypeVar("T")


class History(Generic[T]):
    """`now` is the current state; `push` makes a new one current (and forgets what was undone)."""

    def __init__(self, start: T) -> None:
        self.now = start
        self._undo: list[T] = []
        self._redo: list[T] = []

    def push(self, state: T) -> None:
        self._undo.append(self.now)
        self._redo.clear()
        self.now = state

    def undo(self) -> bool:
        return self._move(self._undo, self._redo)

    def redo(self) -> bool:
        return self._move(self._redo, self._undo)

    def _move(self, src: list[T], dst: list[T]) -> bool:
        """The last state of `src` made current, the current one kept on `dst`; False when `src` is empty."""
        if not src:
            return False
        dst.append(self.now)
        self.now = src.pop()
        return True
