"""Safe file handling: atomic writes and the rule that an input is never overwritten (SPEC §2)."""

from __future__ import annotations

import contextlib
import json
import os
import tempfile
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

from . import limits
from .errors import InputError


def require_file(path: str | os.PathLike[str], *, what: str = "file") -> Path:
    """Return `path` as a Path, or raise InputError if it is missing, a folder or empty."""
    p = Path(path)
    if not p.exists():
        raise InputError(f"{what} not found", p)
    if p.is_dir():
        raise InputError(f"is a folder, expected a {what}", p)
    size = p.stat().st_size
    if size == 0:
        raise InputError(f"{what} is empty", p)
    limits.check("file_mb", size / 1e6, f"{what} is {size / 1e6:,.0f} MB", p)
    return p


def check_output(path: str | os.PathLike[str], inputs: Sequence[str | os.PathLike[str]] = ()) -> Path:
    """Refuse an output path that is one of the inputs or whose folder cannot be made."""
    out = Path(path)
    for i in inputs:
        if Path(i).exists() and out.exists() and os.path.samefile(i, out):
            raise InputError("refusing to overwrite an input file; choose another output", out)
    if out.exists() and out.is_dir():
        raise InputError("output is a folder, expected a file name", out)
    return out


def check_output_folder(path: str | os.PathLike[str]) -> Path:
    """Refuse an output whose folder does not exist (the command line: a mistyped folder is an error, not a new
    folder; library writers create folders as they need them)."""
    out = Path(path)
    if not out.parent.is_dir():
        raise InputError(f"the output's folder {str(out.parent)!r} does not exist (create it first)", out)
    return out


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike[str]) -> Iterator[Path]:
    """Yield a temporary path beside `path`; on success it is renamed onto `path`, on failure removed.

    Readers never see a half-written file, and a failed write leaves the old file as it was.
    """
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{out.name}.", suffix=out.suffix + ".tmp", dir=out.parent)
    os.close(fd)
    tmp_path = Path(tmp)
    try:
        yield tmp_path
        # mkstemp makes 0600 files; give the output the permissions a normal write would (0666 less the umask).
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp_path, 0o666 & ~umask)
        os.replace(tmp_path, out)
    except BaseException:
        tmp_path.unlink(missing_ok=True)
        raise


def write_bytes_atomic(path: str | os.PathLike[str], data: bytes) -> Path:
    with atomic_path(path) as tmp:
        tmp.write_bytes(data)
    return Path(path)


def write_text_atomic(path: str | os.PathLike[str], text: str) -> Path:
    return write_bytes_atomic(path, text.encode("utf-8"))


def write_json_atomic(path: str | os.PathLike[str], obj: Any) -> Path:
    return write_text_atomic(path, json.dumps(obj, indent=1, allow_nan=False) + "\n")


def read_json(path: str | os.PathLike[str], *, what: str = "JSON file") -> Any:
    """Read JSON, turning every failure into an InputError naming the file."""
    p = require_file(path, what=what)
    try:
        text = p.read_text(encoding="utf-8")
    except UnicodeDecodeError:
        raise InputError(f"not a text {what} (not UTF-8)", p) from None
    try:
        return json.loads(text, parse_int=_parse_int)
    except json.JSONDecodeError as e:
        raise InputError(f"invalid JSON at line {e.lineno} column {e.colno}: {e.msg}", p) from None
    except RecursionError:
        raise InputError("invalid JSON: nested too deeply", p) from None


def _parse_int(text: str) -> int | float:
    # An integer past float range (10^400) would break every float() downstream, and Python refuses to parse
    # more than 4300 digits; read such numbers as floats (inf), which the readers' finiteness checks refuse.
    return int(text) if len(text) < 19 else float(text)
