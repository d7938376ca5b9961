"""Render timings: OpenGL context creation and time per frame for a ~50k-triangle mesh.

    python benchmarks/bench_render.py [--frames 10]

Uses GarmentCode's mean_all body (47.5k triangles) from ../shared when it is there, otherwise a procedural sphere
of about 50k triangles. Each figure is the median of --frames renders after one warm-up render (the first frame
compiles the shaders: reported separately). A frame is the whole `Renderer.render` call: framing, normals, upload,
draw, MSAA resolve and read-back into a numpy array.
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

from _timing import timeit

SHARED_BODY = Path(__file__).resolve().parents[2] / "shared/data/bodies/garmentcode/mean_all.obj"


def bench_mesh():
    from kitsuke.geometry import TriMesh, load_mesh

    if SHARED_BODY.exists():
        return load_mesh(SHARED_BODY), f"GarmentCode mean_all ({SHARED_BODY})"
    import trimesh

    m = trimesh.creation.uv_sphere(radius=0.5, count=[112, 113])
    return TriMesh(m.vertices, m.faces, name="sphere"), "procedural UV sphere"


def median_ms(fn, frames: int) -> float:
    return timeit(fn, frames) * 1000.0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--frames", type=int, default=10, help="timed renders per case (default 10)")
    args = parser.parse_args()

    from kitsuke.render import DEFAULT_SIZE, Renderer, render_sheet

    t = time.perf_counter()
    renderer = Renderer()
    first_ctx = time.perf_counter() - t
    t = time.perf_counter()
    Renderer().close()
    second_ctx = time.perf_counter() - t

    mesh, source = bench_mesh()
    print(f"renderer: {renderer.renderer_name}; CPUs: {os.cpu_count()}; MSAA max {renderer.max_samples}")
    print(f"mesh: {source}: {mesh.n_vertices} vertices, {mesh.n_faces} triangles")
    print(f"context creation: first {first_ctx * 1000:.0f} ms (loads EGL/Mesa), another {second_ctx * 1000:.0f} ms")
    t = time.perf_counter()
    renderer.render(mesh, size=(64, 64))
    print(f"first frame (shader compile): {(time.perf_counter() - t) * 1000:.0f} ms")

    cases = [
        ("MSAA 4 (default)", {}),
        ("no MSAA", {"samples": 1}),
        ("transparent RGBA", {"background": None}),
        ("wireframe", {"wireframe": True}),
        ("supersample 2 + MSAA 4", {"supersample": 2}),
    ]
    sizes = [(1280, 720), DEFAULT_SIZE]
    print(f"\nms per frame (median of {args.frames})".ljust(34) + "".join(f"{w}x{h}".rjust(12) for w, h in sizes))
    for label, options in cases:
        row = [median_ms(lambda s=s, o=options: renderer.render(mesh, size=s, **o), args.frames) for s in sizes]
        print(f"  {label}".ljust(34) + "".join(f"{v:12.1f}" for v in row))
    sheet_ms = median_ms(lambda: render_sheet(mesh, renderer=renderer, size=(400, 500)), max(3, args.frames // 3))
    print(f"  contact sheet front/side/back 3x400x500: {sheet_ms:.0f} ms")

    # Where the time goes at the default size: CPU-side preparation vs the GPU (llvmpipe) work.
    prep = median_ms(lambda: mesh.vertex_normals, args.frames)
    print(f"  of which vertex normals (numpy): {prep:.1f} ms")
    renderer.close()


if __name__ == "__main__":
    main()
