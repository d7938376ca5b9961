"""Argument helpers shared by the CLI groups (kept tiny: the behaviour lives in the library)."""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from pathlib import Path

from .._files import check_output, check_output_folder
from ..errors import InputError


def add_body_options(p: argparse.ArgumentParser) -> None:
    g = p.add_argument_group("body units and axes (default: detected)")
    g.add_argument(
        "--units",
        default="auto",
        choices=["auto", "m", "dm", "cm", "mm", "in"],
        help="length unit of the body file",
    )
    g.add_argument(
        "--up",
        default="auto",
        choices=["auto", "+x", "-x", "+y", "-y", "+z", "-z"],
        help="the file's axis that points up (head)",
    )
    g.add_argument(
        "--facing",
        default="auto",
        choices=["auto", "+x", "-x", "+y", "-y", "+z", "-z"],
        help="the file's axis the person faces",
    )
    g.add_argument("--group", default=None, help="keep only this OBJ group (e.g. `body` of a MakeHuman base mesh)")


def body_from_args(args: argparse.Namespace, attr: str = "body"):
    """Load the body named by args.<attr>: a file, or `default` for the packaged one."""
    from ..body import default_body, load_body

    name = getattr(args, attr)
    if name == "default":
        return default_body()
    return load_body(name, units=args.units, up=args.up, facing=args.facing, group=args.group)


def checked_output(path: str, inputs: Sequence[str], *, suffixes: Sequence[str] = ()) -> Path:
    """Validate an output path: a known suffix, not an input, not a folder, in a folder that exists."""
    out = Path(path)
    if suffixes and out.suffix.lower() not in suffixes:
        raise InputError(f"output must end in {', '.join(suffixes)}", out)
    return check_output_folder(check_output(out, [i for i in inputs if i != "default"]))
