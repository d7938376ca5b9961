"""Error types shared by the library and the command line.

`InputError` is what bad input raises anywhere in kitsuke; the CLI turns it into one line on stderr and exit code 2.
`ComputationError` is a computation that gave no usable result (diverged, non-finite, not a garment on the body);
the CLI says which stage failed in one line, writes nothing as if it worked, and exits with code 1. Anything else
escaping to the CLI is an internal error (exit code 1).
"""

from __future__ import annotations

from os import PathLike


class KitsukeError(Exception):
    """Base class of kitsuke's own errors."""


class InputError(KitsukeError, ValueError):
    """Bad input: a file or an argument that kitsuke cannot use.

    Parameters
    ----------
    message : what is wrong, one line, without the file name.
    path : the file (or argument) that is wrong, if there is one; it prefixes the message.
    """

    def __init__(self, message: str, path: str | PathLike[str] | None = None):
        self.message = message
        self.path = None if path is None else str(path)
        super().__init__(f"{self.path}: {message}" if self.path else message)


def require_non_negative(settings: object, label: str, *names: str) -> None:
    """InputError unless each attribute `names` of `settings` is a finite number >= 0 (settings groups check
    their constants with it: "dynamics parameter damping must be a finite number >= 0, got nan")."""
    import math
    from numbers import Real

    for name in names:
        v = getattr(settings, name)
        if isinstance(v, bool) or not isinstance(v, Real) or not (math.isfinite(v) and v >= 0):
            raise InputError(f"{label} {name} must be a finite number >= 0, got {v!r}")


class ComputationError(KitsukeError, RuntimeError):
    """A computation that gave no usable result: it diverged, went non-finite, or its result is not what it
    should be (a garment that is not on the body).

    Parameters
    ----------
    stage : the step that failed ("length restoration", "wrap: close", ...).
    message : what went wrong, one line, naming the piece or stroke where there is one.
    result : the unusable result, for inspection (`kitsuke dress --keep-failed` writes it), or None.
    """

    def __init__(self, stage: str, message: str, *, result: object = None):
        self.stage = stage
        self.message = message
        self.result = result
        super().__init__(f"{stage}: {message}")
