"""Body benchmarks: loading (default body, OBJ/GLB/PLY files with detection and cleaning) and posing (LBS).

    python benchmarks/bench_body.py

Prints one line per measurement: the median of several runs after a warm-up.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np
from _timing import timeit

from kitsuke.body import default_body, load_body
from kitsuke.geometry import load_mesh, save_mesh

ROOT = Path(__file__).resolve().parents[1]
MEAN_ALL = ROOT / "tests" / "data" / "bodies" / "mean_all.obj"


def main() -> None:
    body = default_body()
    print(f"default_body() (npz, 13,380 vertices, rig + capsules)    {timeit(default_body) * 1e3:8.1f} ms")
    with tempfile.TemporaryDirectory() as tmp:
        mesh = load_mesh(MEAN_ALL)
        for suffix in (".obj", ".glb", ".ply"):
            path = save_mesh(mesh, Path(tmp) / f"mean_all{suffix}")
            t = timeit(lambda p=path: load_body(p), repeat=5)
            print(f"load_body mean_all{suffix:5s} (23,752 vertices, detect + clean)  {t * 1e3:8.1f} ms")
        cm = save_mesh(type(mesh)(mesh.vertices * 100, mesh.faces), Path(tmp) / "mean_all_cm.obj")
        print(
            f"load_body mean_all in cm (converted)                     {timeit(lambda: load_body(cm), 5) * 1e3:8.1f} ms"
        )
    rot = {"l_knee": [np.pi / 2, 0, 0], "r_shoulder": [0, 0, -0.6], "spine": [0.2, 0, 0]}
    t = timeit(lambda: body.pose(rotations=rot))
    print(f"Body.pose(rotations=...) default body (LBS)              {t * 1e3:8.2f} ms")
    target = body.pose(rotations=rot).joints
    t = timeit(lambda: body.pose(positions=target))
    print(f"Body.pose(positions=...) default body                    {t * 1e3:8.2f} ms")


if __name__ == "__main__":
    main()
