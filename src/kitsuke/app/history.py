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
        if not self._undo:
            return False
        self._redo.append(self.now)
        self.now = self._undo.pop()
        return True

    def redo(self) -> bool:
        if not self._redo:
            return False
        self._undo.append(self.now)
        self.now = self._redo.pop()
        return True
