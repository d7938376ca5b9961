"""The options of a dress, as a user gives them (`kitsuke dress` flags, a batch manifest's columns), and the
WrapParams they stand for. One place, so that a garment dressed by `kitsuke dress` and by `kitsuke batch dress`
with the same options is the same garment."""

from __future__ import annotations

import ast
from collections.abc import Callable
from dataclasses import dataclass

from ..errors import InputError
from .wrap import WrapParams


@dataclass(frozen=True)
class DressOptions:
    """What a user chooses about a wrap (see `kitsuke dress --help` for each one's why).

    edge_length : target triangle edge length of the garment mesh, cm (0.2-10).
    stroke_reach : how far a pattern stroke may settle from its body stroke, mm (0-100; 0: settle freely).
    hold_strokes : keep the garment hanging from its strokes instead of letting it settle.
    hang : how strongly cloth growing off the body turns down (0-10), or None: 2 for a kimono, 0 otherwise.
    no_polish : skip the polish (faster; the max strain stays where the settle left it).
    settings : any of the wrap's settings by dotted name, applied last (`WrapParams.changed`; `parse_setting`
        reads "polish.rounds=0" as a user writes it).
    """

    edge_length: float = 1.5
    stroke_reach: float = 8.0
    hold_strokes: bool = False
    hang: float | None = None
    no_polish: bool = False
    settings: tuple[tuple[str, object], ...] = ()

    def check(self, spell: Callable[[str], str] = lambda name: name) -> None:
        """Raise InputError for a value out of its range; `spell` turns a field name into what the user wrote
        (`--edge-length` on the command line, `edge_length` in a manifest)."""
        if not 0.2 <= self.edge_length <= 10:
            raise InputError(f"{spell('edge_length')} must be between 0.2 and 10 cm, got {self.edge_length}")
        if not 0 <= self.stroke_reach <= 100:
            raise InputError(f"{spell('stroke_reach')} must be between 0 and 100 mm, got {self.stroke_reach}")
        if self.hang is not None and not 0 <= self.hang <= 10:
            raise InputError(f"{spell('hang')} must be between 0 and 10, got {self.hang}")
        try:
            WrapParams().changed(dict(self.settings))
        except (InputError, TypeError) as e:
            raise InputError(f"{spell('settings')}: {e}") from None

    def wrap_params(self, body, pattern) -> WrapParams:
        """The WrapParams of these options for `pattern` on `body` (a kimono gets its hang, offset and obi band)."""
        from .kimono import is_kimono, kimono_params

        make = WrapParams.strokes_held if self.hold_strokes else WrapParams
        reach = self.stroke_reach * 1e-3 if self.stroke_reach > 0 else None
        params = make(edge_length_cm=self.edge_length).changed(
            {"tethers.reach_m": reach, "grow.hang": self.hang or 0.0}
        )
        if self.no_polish:
            params = params.changed({"polish.rounds": 0})
        if is_kimono(pattern):
            params = kimono_params(body, params, hang=self.hang)
        return params.changed(dict(self.settings))


def parse_setting(text: str) -> tuple[str, object]:
    """("polish.rounds", 0) from "polish.rounds=0": the value read as a Python literal (numbers, True, None,
    tuples), else kept as text ("settle.method=global"). InputError without a '='."""
    name, sep, value = text.partition("=")
    if not sep or not name.strip():
        raise InputError(f"a wrap setting is NAME=VALUE (e.g. polish.rounds=0), got {text!r}")
    try:
        return name.strip(), ast.literal_eval(value.strip())
    except (ValueError, SyntaxError):
        return name.strip(), value.strip()
