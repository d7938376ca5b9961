"""Fuzzing kitsuke's readers: what each reader does with a file, seed files to mutate, mutations, and a guarded
worker process that runs one case at a time with a time and memory bound.

A *target* is one input format and what a command does with such a file (read, validate, and for patterns mesh);
every case must end in success or one `InputError` of one line that names the file. Anything else is a finding:
another exception ("crash"), a multi-line or anonymous InputError ("bad-error"), more than `timeout_s` ("hang") or
more than `max_rss_bytes` of memory ("memory").

Used by tests/fuzz (a few examples per target, in CI) and benchmarks/fuzz_inputs.py (10^4 per target).
"""

from __future__ import annotations

import copy
import json
import math
import multiprocessing as mp
import re
import tempfile
import time
import traceback
from collections.abc import Callable
from dataclasses import dataclass
from functools import cache
from pathlib import Path

import numpy as np

DATA = Path(__file__).resolve().parent.parent / "data"

#: Bounds of one case (issue 30): a hang is past 10 s, memory past 2 GB.
TIMEOUT_S = 10.0
MAX_RSS_BYTES = 2 * 1024**3


# -- what a command does with each kind of file --------------------------------------------------------------
def _read_pattern(path: Path) -> None:
    from kitsuke.pattern import load_pattern, mesh_pattern

    mesh_pattern(load_pattern(path))


def _read_body(path: Path) -> None:
    from kitsuke.body import load_body

    load_body(path)


@cache
def _kimono_context():
    from kitsuke.body import default_body
    from kitsuke.geometry.surface import Surface
    from kitsuke.pattern import default_kimono, mesh_pattern

    pattern = default_kimono()
    return pattern, mesh_pattern(pattern), Surface.of(default_body().mesh)


def _read_strokes(path: Path) -> None:
    from kitsuke.dressing import read_strokes, resolve_strokes

    pattern, mesh, surface = _kimono_context()
    resolve_strokes(read_strokes(path), pattern, surface, pattern_mesh=mesh)


def _read_garment(path: Path) -> None:
    from kitsuke.dressing.export import read_garment_obj

    read_garment_obj(path)


def _read_drags(path: Path) -> None:
    from kitsuke.dressing import read_drags

    read_drags(path)


def _read_poses(path: Path) -> None:
    from kitsuke.pose import read_poses

    read_poses(path)


def _read_bvh(path: Path) -> None:
    from kitsuke.pose import load_bvh

    load_bvh(path)


def _read_constraints(path: Path) -> None:
    from kitsuke.pose import read_constraints

    read_constraints(path)


# -- seed files ------------------------------------------------------------------------------------------------
@cache
def _small_body():
    """The default body clustered onto a 3 cm grid: the same person in ~1,500 triangles, so that a byte mutation
    lands on structure as often as on a coordinate."""
    from kitsuke.body import default_body
    from kitsuke.geometry.mesh import TriMesh

    mesh = default_body().mesh
    cell = np.floor(mesh.vertices / 0.03).astype(np.int64)
    _, first, inverse = np.unique(cell, axis=0, return_index=True, return_inverse=True)
    faces = inverse.reshape(-1)[mesh.faces]
    keep = (faces[:, 0] != faces[:, 1]) & (faces[:, 1] != faces[:, 2]) & (faces[:, 0] != faces[:, 2])
    faces = np.unique(np.sort(faces[keep], axis=1), axis=0)
    return TriMesh(mesh.vertices[first], faces, None, name="body")


def _mesh_bytes(suffix: str) -> bytes:
    from kitsuke.geometry.io import save_mesh

    with tempfile.TemporaryDirectory() as d:
        return save_mesh(_small_body(), Path(d) / f"body{suffix}").read_bytes()


def _kimono_json() -> bytes:
    from kitsuke.pattern import default_kimono, save_pattern

    with tempfile.TemporaryDirectory() as d:
        return save_pattern(default_kimono(), Path(d) / "kimono.json").read_bytes()


def _garment_obj() -> bytes:
    """A garment OBJ as `kitsuke dress --obj` writes it (pieces, a layer, the contact offset): the kimono's pieces
    at their placement, meshed coarsely (the reader's work does not depend on a wrap)."""
    from kitsuke.dressing.export import GarmentFile, garment_obj_text
    from kitsuke.pattern import default_kimono, mesh_pattern

    mesh = mesh_pattern(default_kimono(), edge_length=8.0)
    layer = np.zeros(len(mesh.faces), np.int8)
    layer[mesh.piece_faces[1, 0] : mesh.piece_faces[1, 1]] = 1
    garment = GarmentFile(
        mesh.positions_m,
        mesh.faces,
        mesh.vertices_cm[mesh.faces] / 100.0,
        list(mesh.piece_names),
        mesh.piece_faces,
        "kimono",
        layer,
        0.003,
    )
    return garment_obj_text(garment).encode()


def _packaged(*parts: str) -> bytes:
    from importlib import resources

    return (resources.files("kitsuke.assets").joinpath(*parts)).read_bytes()


def _drags_json() -> bytes:
    from kitsuke.dressing import Drags, DragStep, drags_to_json

    steps = [
        DragStep(None, [[0.0, 1.2, -0.1], [0.05, 1.2, -0.1]], None, []),
        DragStep(None, None, [0.0, 1.1, 0.12], [[0.0, 1.13, 0.12], [0.0, 1.16, 0.12]]),
        DragStep("all", None, None, []),
    ]
    return drags_to_json(Drags(steps, {"note": "fuzz seed"})).encode()


def _poses_json() -> bytes:
    from kitsuke.pose import load_bvh, poses_to_json

    poses = load_bvh(DATA / "pose" / "makehuman_standing01_pose.bvh", max_frames=3)
    return json.dumps(poses_to_json(poses), indent=1).encode()


def _bvh_text() -> bytes:
    """The CMU kick clip cut to its hierarchy and 4 frames (the reader's work is per frame)."""
    text = (DATA / "pose" / "cmu_10_01_soccer_kick_mh.bvh").read_text()
    head, motion = text.split("MOTION", 1)
    lines = motion.strip().splitlines()
    frames = [ln for ln in lines[2:] if ln.strip()][:4]
    return (head + "MOTION\nFrames: 4\n" + lines[1] + "\n" + "\n".join(frames) + "\n").encode()


@dataclass(frozen=True)
class Target:
    """One input format. `read(path)` does what the commands do with such a file; `seeds()` gives valid files
    to mutate; `kind` picks the structure-aware mutations ("json", "text" or "binary")."""

    name: str
    suffix: str
    kind: str
    read: Callable[[Path], None]
    seeds: Callable[[], list[bytes]]


TARGETS: dict[str, Target] = {
    t.name: t
    for t in [
        Target(
            "pattern-kitsuke",
            ".json",
            "json",
            _read_pattern,
            lambda: [_kimono_json(), (DATA / "pattern" / "teagan_tshirt_cisMaleAdult42_sewn.json").read_bytes()],
        ),
        Target(
            "pattern-garmentcode",
            ".json",
            "json",
            _read_pattern,
            lambda: [
                (DATA / "pattern" / "shirt_mean_specification.json").read_bytes(),
                (DATA / "pattern" / "corpus" / "gc_s202_0022_specification.json").read_bytes(),
            ],
        ),
        Target(
            "pattern-svg",
            ".svg",
            "text",
            _read_pattern,
            lambda: [(DATA / "pattern" / "teagan_tshirt_cisMaleAdult42.svg").read_bytes()],
        ),
        Target("body-obj", ".obj", "text", _read_body, lambda: [_mesh_bytes(".obj")]),
        Target("body-glb", ".glb", "binary", _read_body, lambda: [_mesh_bytes(".glb")]),
        Target("body-ply", ".ply", "binary", _read_body, lambda: [_mesh_bytes(".ply")]),
        Target("strokes", ".json", "json", _read_strokes, lambda: [_packaged("strokes", "kimono_default.json")]),
        Target("garment-obj", ".obj", "text", _read_garment, lambda: [_garment_obj()]),
        Target("drags", ".json", "json", _read_drags, lambda: [_drags_json()]),
        Target("poses", ".json", "json", _read_poses, lambda: [_poses_json()]),
        Target("bvh", ".bvh", "text", _read_bvh, lambda: [_bvh_text()]),
        Target(
            "constraints",
            ".json",
            "json",
            _read_constraints,
            lambda: [_packaged("constraints", "kimono_standard_geometric.json")],
        ),
    ]
}


# -- mutations -------------------------------------------------------------------------------------------------
#: Values a hostile or careless file holds where a number, string or structure was expected.
NASTY_VALUES: list = [
    math.nan,
    math.inf,
    -math.inf,
    0,
    -1,
    1e-300,
    1e9,
    -1e9,
    1e308,
    10**400,
    2**63,
    "",
    "x",
    "circle",
    None,
    True,
    [],
    {},
    [[]],
    [0, 0],
    [1e9, 1e9],
    {"x": 1},
]

#: Number spellings dropped into text formats (OBJ, PLY headers, BVH, SVG paths).
NASTY_NUMBERS: list[str] = [
    "nan",
    "inf",
    "-inf",
    "0",
    "-1",
    "-0",
    "1e9",
    "-1e9",
    "1e308",
    "1e999",
    "4294967296",
    "99999999999999999999",
    "1.5.5",
    "",
    "0x10",
    "1e-320",
]


def _paths(node, prefix=()):
    """Every (path, value) of a parsed JSON document, the root first."""
    yield prefix, node
    if isinstance(node, dict):
        for k, v in node.items():
            yield from _paths(v, (*prefix, k))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            yield from _paths(v, (*prefix, i))


def _get(doc, path):
    for k in path:
        doc = doc[k]
    return doc


def mutate_json(seed: bytes, ops: list[tuple[str, int, object]]) -> bytes:
    """Apply structure-aware operations to a JSON document. Each op is (action, which node, value):
    replace the node by value, delete it, add an extra key, duplicate (e.g. a piece: duplicate names), drop or
    swap list items (outline points: self-intersections), copy a value under another key, or wrap it in a list.
    Numbers like NaN and 10^400 go out as JSON spells them (NaN, Infinity, a 400-digit integer)."""
    doc = json.loads(seed)
    for action, which, value in ops:
        value = copy.deepcopy(value)  # never mutate the shared NASTY_VALUES (a list would come to hold itself)
        nodes = list(_paths(doc))
        path, node = nodes[which % len(nodes)]
        if not path:
            if action == "replace":
                doc = value
            continue
        parent = _get(doc, path[:-1])
        key = path[-1]
        if action == "replace":
            parent[key] = value
        elif action == "delete":
            del parent[key]
        elif action == "extra" and isinstance(node, dict):
            node["unexpected_" + str(which % 7)] = value
        elif action == "duplicate" and isinstance(node, list) and node:
            node.extend(node[: 1 + which % len(node)] * (1 + which % 3))
        elif action == "truncate" and isinstance(node, list):
            del node[len(node) // 2 :]
        elif action == "rename" and isinstance(parent, dict):
            others = [k for k in parent if k != key]
            if others:
                parent[others[which % len(others)]] = node
        elif action == "wrap":
            parent[key] = [node]
        elif action == "swap" and isinstance(node, list) and len(node) > 1:
            i, j = which % len(node), (which // len(node)) % len(node)
            node[i], node[j] = node[j], node[i]  # outline points swapped: a self-intersecting outline
        elif action == "scale" and isinstance(node, int | float) and not isinstance(node, bool):
            factor = value if isinstance(value, float) else 1e6
            parent[key] = node * factor if math.isfinite(node * factor) else factor
    return json.dumps(doc, allow_nan=True).encode()


JSON_ACTIONS = ("replace", "delete", "extra", "duplicate", "truncate", "rename", "wrap", "scale", "swap")

_NUMBER = re.compile(rb"-?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?")


def mutate_text(seed: bytes, ops: list[tuple[str, int, int]]) -> bytes:
    """Apply token-aware operations to a text format: replace the k-th number by a nasty spelling, delete,
    duplicate or swap a line, or cut the file at a line."""
    data = seed
    for action, which, choice in ops:
        if action == "number":
            spans = [m.span() for m in _NUMBER.finditer(data)]
            if spans:
                a, b = spans[which % len(spans)]
                data = data[:a] + NASTY_NUMBERS[choice % len(NASTY_NUMBERS)].encode() + data[b:]
            continue
        lines = data.split(b"\n")
        i = which % len(lines)
        if action == "delete-line":
            del lines[i]
        elif action == "duplicate-line":
            lines[i:i] = [lines[i]] * (1 + choice % 50)
        elif action == "swap-lines":
            j = choice % len(lines)
            lines[i], lines[j] = lines[j], lines[i]
        elif action == "cut":
            del lines[i:]
        data = b"\n".join(lines)
    return data


TEXT_ACTIONS = ("number", "delete-line", "duplicate-line", "swap-lines", "cut")


def mutate_bytes(seed: bytes, ops: list[tuple[str, int, bytes]]) -> bytes:
    """Raw byte mutations: flip bits, overwrite, insert, delete a range, truncate, or repeat a chunk."""
    data = bytearray(seed)
    for action, where, payload in ops:
        if not data:
            data = bytearray(payload)
            continue
        i = where % len(data)
        if action == "flip":
            data[i] ^= 1 << (where % 8)
        elif action == "overwrite":
            data[i : i + len(payload)] = payload
        elif action == "insert":
            data[i:i] = payload
        elif action == "delete":
            del data[i : i + 1 + where % 64]
        elif action == "truncate":
            del data[i:]
        elif action == "repeat":
            data[i:i] = data[i : i + 1 + where % 256] * (1 + where % 4)
    return bytes(data)


BYTE_ACTIONS = ("flip", "overwrite", "insert", "delete", "truncate", "repeat")

#: 32-bit little-endian integers that make binary headers lie (counts and lengths).
NASTY_U32 = [
    (0).to_bytes(4, "little"),
    (1).to_bytes(4, "little"),
    (0x7FFFFFFF).to_bytes(4, "little"),
    (0xFFFFFFFF).to_bytes(4, "little"),
    (0x10000000).to_bytes(4, "little"),
]


# -- running one case, guarded ---------------------------------------------------------------------------------
@dataclass(frozen=True)
class Outcome:
    """How one case ended: "ok", "input-error" (both fine), or a finding: "crash", "bad-error", "hang",
    "memory". `detail` is the error line or the traceback's last lines; `seconds` the time it took."""

    status: str
    detail: str = ""
    seconds: float = 0.0

    @property
    def fine(self) -> bool:
        return self.status in ("ok", "input-error")


def run_case(target_name: str, data: bytes, folder: str) -> Outcome:
    """Run one case in this process (the worker calls this): write `data` to a file and read it."""
    from kitsuke.errors import InputError

    target = TARGETS[target_name]
    path = Path(folder) / f"case{target.suffix}"
    path.write_bytes(data)
    t0 = time.perf_counter()
    try:
        target.read(path)
    except InputError as e:
        text = str(e)
        dt = time.perf_counter() - t0
        if "\n" in text or "\r" in text:
            return Outcome("bad-error", f"InputError of several lines: {text[:300]!r}", dt)
        if str(path) not in text:
            return Outcome("bad-error", f"InputError not naming the file: {text[:300]}", dt)
        return Outcome("input-error", text.replace(str(path), "FILE"), dt)
    except Exception as e:  # noqa: BLE001 - any other exception is what the fuzzing looks for
        tb = traceback.extract_tb(e.__traceback__)
        where = "; ".join(f"{Path(f.filename).name}:{f.lineno} {f.name}" for f in tb[-3:])
        return Outcome("crash", f"{type(e).__name__}: {str(e)[:200]} [{where}]", time.perf_counter() - t0)
    return Outcome("ok", "", time.perf_counter() - t0)


def _serve(conn) -> None:
    import warnings

    warnings.simplefilter("ignore")  # trimesh and numpy warn about odd files; the outcome is what counts
    with tempfile.TemporaryDirectory(prefix="kitsuke-fuzz-") as folder:
        while True:
            msg = conn.recv()
            if msg is None:
                return
            conn.send(run_case(*msg, folder))


def _rss_bytes(pid: int) -> int:
    try:
        with open(f"/proc/{pid}/status") as f:
            for line in f:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    return 0


class Worker:
    """A child process that runs cases one at a time. A case past `timeout_s` or `max_rss_bytes` kills the
    child (a fresh one starts for the next case), so a hang or a memory blow-up is a finding, not a stuck
    suite."""

    def __init__(self, timeout_s: float = TIMEOUT_S, max_rss_bytes: int = MAX_RSS_BYTES):
        self.timeout_s = timeout_s
        self.max_rss_bytes = max_rss_bytes
        self._proc = None
        self._conn = None

    def _start(self) -> None:
        ctx = mp.get_context("spawn")  # a clean interpreter: no numba threads or pytest state inherited
        self._conn, child = ctx.Pipe()
        self._proc = ctx.Process(target=_serve, args=(child,), daemon=True)
        self._proc.start()
        child.close()

    def warm(self, target_name: str, data: bytes) -> None:
        """Run one case without a time bound: imports and numba compilation are not the case's time."""
        if self._proc is None:
            self._start()
        self._conn.send((target_name, data))
        self._conn.recv()

    def run(self, target_name: str, data: bytes) -> Outcome:
        if self._proc is None or not self._proc.is_alive():
            self._start()
            self.warm(target_name, TARGETS[target_name].seeds()[0])
        t0 = time.perf_counter()
        self._conn.send((target_name, data))
        while True:
            if self._conn.poll(0.05):
                try:
                    return self._conn.recv()
                except EOFError:
                    break
            elapsed = time.perf_counter() - t0
            if not self._proc.is_alive():
                break
            if elapsed > self.timeout_s:
                self._kill()
                return Outcome("hang", f"no answer after {self.timeout_s:g} s", elapsed)
            if _rss_bytes(self._proc.pid) > self.max_rss_bytes:
                self._kill()
                return Outcome("memory", f"over {self.max_rss_bytes / 1024**3:g} GB", elapsed)
        code = self._proc.exitcode
        self._kill()
        return Outcome("crash", f"the reader killed its process (exit code {code})", time.perf_counter() - t0)

    def _kill(self) -> None:
        if self._proc is not None:
            self._proc.kill()
            self._proc.join()
        self._proc = self._conn = None

    def close(self) -> None:
        if self._proc is not None and self._proc.is_alive():
            self._conn.send(None)
            self._proc.join(5)
        self._kill()


def summary(outcomes: list[Outcome]) -> dict[str, int]:
    counts: dict[str, int] = {}
    for o in outcomes:
        counts[o.status] = counts.get(o.status, 0) + 1
    return counts
