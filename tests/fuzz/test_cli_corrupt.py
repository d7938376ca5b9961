"""Every command, fed a corrupt file in each of its file arguments: exit 2, one line on stderr, no traceback, and
an output that existed before is left as it was.

Corruptions: an empty file, the valid file cut in half, binary junk, and the wrong format under the right
extension (another kind of JSON, a PLY under .obj, text under .mp4, ...).
"""

from __future__ import annotations

import random

import pytest

from .harness import DATA, TARGETS
from .strategies import seeds

pytestmark = pytest.mark.slow

SENTINEL = b"an output written before this run\n"


def _valid(kind: str) -> tuple[str, bytes]:
    """(suffix, bytes) of a valid input of each kind the commands take."""
    if kind == "video":
        return ".mp4", (DATA / "pose" / "pose2sim_static_tpose_cam01.mp4").read_bytes()
    if kind == "image":
        return ".png", _png()
    target = {
        "body": "body-obj",
        "pattern": "pattern-kitsuke",
        "strokes": "strokes",
        "drags": "drags",
        "bvh": "bvh",
        "poses": "poses",
        "constraints": "constraints",
        "garment": "body-obj",
    }[kind]
    return TARGETS[target].suffix, seeds(target)[0]


def _png() -> bytes:
    import io

    import numpy as np
    from PIL import Image

    buf = io.BytesIO()
    Image.fromarray(np.full((64, 48, 3), 200, np.uint8)).save(buf, format="PNG")
    return buf.getvalue()


def _wrong_format(kind: str) -> bytes:
    """A well-formed file of another kind, under this kind's extension."""
    if kind in ("pattern", "strokes", "drags", "poses", "constraints"):
        other = "drags" if kind != "drags" else "strokes"
        return seeds(other)[0]
    if kind in ("body", "garment"):
        return seeds("body-ply")[0]
    if kind == "bvh":
        return seeds("poses")[0]
    return seeds("bvh")[0]  # a video: text


CORRUPTIONS = {
    "empty": lambda kind, data: b"",
    "truncated": lambda kind, data: data[: len(data) // 2],
    "junk": lambda kind, data: random.Random(len(data)).randbytes(2048),
    "wrong-format": lambda kind, data: _wrong_format(kind),
}

#: command line with {slot} placeholders -> the slot being corrupted; {out} is the output that must survive.
COMMANDS = [
    ("body info {body}", "body"),
    ("body convert {body} {out}.glb", "body"),
    ("pattern validate {pattern}", "pattern"),
    ("pattern convert {pattern} {out}.svg", "pattern"),
    ("pattern mesh {pattern} -o {out}.obj", "pattern"),
    ("strokes suggest --body {body} --pattern {pattern} -o {out}.json", "body"),
    ("strokes suggest --body {body} --pattern {pattern} -o {out}.json", "pattern"),
    ("strokes check --body {body} --pattern {pattern} --strokes {strokes}", "strokes"),
    ("dress --body {body} --pattern {pattern} --strokes {strokes} -o {out}.glb", "body"),
    ("dress --body {body} --pattern {pattern} --strokes {strokes} -o {out}.glb", "pattern"),
    ("dress --body {body} --pattern {pattern} --strokes {strokes} -o {out}.glb", "strokes"),
    ("drag --body {body} --garment {garment} --drags {drags} -o {out}.obj", "drags"),
    ("drag --body {body} --garment {garment} --drags {drags} -o {out}.obj", "garment"),
    ("render {body} -o {out}.png", "body"),
    ("pose extract {bvh} -o {out}.json", "bvh"),
    ("pose extract {poses} -o {out}.json", "poses"),
    ("pose extract {video} -o {out}.json", "video"),
    ("pose extract {image} -o {out}.json", "image"),
    ("render default --texture {image} -o {out}.png", "image"),
    ("pose correct {poses} -o {out}.json --constraints {constraints}", "constraints"),
]


@pytest.mark.parametrize("corruption", sorted(CORRUPTIONS))
@pytest.mark.parametrize(("command", "slot"), COMMANDS, ids=[f"{c.split(' {')[0]}-{s}" for c, s in COMMANDS])
def test_corrupt_input(command, slot, corruption, tmp_path, run_cli):
    files = {}
    for kind in ("body", "pattern", "strokes", "drags", "bvh", "poses", "constraints", "garment", "video", "image"):
        if "{" + kind + "}" not in command:
            continue
        suffix, data = _valid(kind)
        if kind == slot:
            data = CORRUPTIONS[corruption](kind, data)
        path = tmp_path / f"{kind}{suffix}"
        path.write_bytes(data)
        files[kind] = str(path)
    out = tmp_path / "previous"
    args = command.format(out=out, **files).split()
    outputs = [a for a in args if a.startswith(str(out))]
    for o in outputs:
        with open(o, "wb") as f:
            f.write(SENTINEL)
    result = run_cli(*args)
    if corruption == "truncated" and files[slot].endswith(".obj") and result.code == 0:
        # OBJ has no length or count to check a file against: one cut at a line end is a smaller mesh.
        return
    assert result.code == 2, result.err
    lines = result.err.strip().splitlines()
    assert len(lines) == 1, result.err
    assert "Traceback" not in result.err and "internal error" not in result.err
    assert files[slot] in lines[0] or f"{slot}" in lines[0].lower(), lines[0]
    for o in outputs:
        with open(o, "rb") as f:
            assert f.read() == SENTINEL, f"{o} was changed"
