"""The demo behind `kitsuke demo`: the built-in body and kimono, end to end, into one folder.

The kimono (`default_kimono()`) is drawn as a pattern, meshed, shown on a stand (its placement hint), then dressed
on the default body with the packaged strokes, its waist held where the obi goes: the files a user looks at first.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path


@dataclass
class DemoResult:
    """What the demo wrote (path -> one-line description) and how long each step took (seconds)."""

    files: dict[Path, str] = field(default_factory=dict)
    timings_s: dict[str, float] = field(default_factory=dict)


def run_demo(out_dir: str | Path = "out", *, size: tuple[int, int] = (800, 1000)) -> DemoResult:
    """Load the default body, make and mesh the standard kimono, and write the results into `out_dir`.

    Writes: body.glb; kimono.json / .svg / .png (pattern with edges and seams), kimono_textured.png (flat pattern
    with its asanoha texture); kimono.obj (Triangle mesh, 1.5 cm edges, vt = pattern metres); body_front.png,
    body_side.png; kimono_on_stand.png (the textured kimono at its placement hint around the body); and the
    dressed kimono: dressed.glb (textured kimono + body), dressed.obj (SPEC §3.3), dressed_report.json (quality,
    stroke residuals, timings) and dressed.png (front / side / back).
    size : (width, height) of the renders in pixels.
    """
    from .body import default_body
    from .dressing.export import garment_glb_mesh, write_garment_glb, write_garment_obj, write_garment_report
    from .dressing.kimono import dress_default_kimono
    from .geometry import save_mesh
    from .pattern import (
        default_kimono,
        kimono_texture,
        mesh_pattern,
        mesh_quality,
        save_pattern,
        texture_tile_size_cm,
        write_pattern_obj,
    )
    from .render import Renderer, render_sheet, write_png

    out = Path(out_dir)
    result = DemoResult()

    def step(name: str, t0: float) -> None:
        result.timings_s[name] = round(time.perf_counter() - t0, 3)

    t = time.perf_counter()
    body = default_body()
    result.files[save_mesh(body.mesh, out / "body.glb")] = (
        f"default body, {body.mesh.n_vertices} vertices, {body.height_m:.2f} m, rigged (23 joints)"
    )
    step("body", t)

    t = time.perf_counter()
    kimono = default_kimono()
    result.files[save_pattern(kimono, out / "kimono.json")] = (
        f"kimono pattern, {len(kimono.pieces)} pieces, {len(kimono.seams)} seams"
    )
    result.files[save_pattern(kimono, out / "kimono.svg")] = "pattern drawing, true size (1 unit = 1 cm)"
    result.files[save_pattern(kimono, out / "kimono.png")] = "pattern drawing with edge numbers and seams"
    result.files[save_pattern(kimono, out / "kimono_textured.png", texture="asanoha", annotate=False)] = (
        "flat pattern with its asanoha texture"
    )
    step("pattern", t)

    t = time.perf_counter()
    mesh = mesh_pattern(kimono)
    write_pattern_obj(mesh, out / "kimono.obj", seams=kimono.seams)
    q = mesh_quality(mesh)
    result.files[out / "kimono.obj"] = (
        f"meshed pattern, {len(mesh.faces)} triangles, min angle {q['min_angle_away_deg']:.1f} deg "
        f"({q['min_angle_deg']:.1f} at the {q['sharpest_corner_deg']:.0f} deg okumi points)"
    )
    step("mesh", t)

    t = time.perf_counter()
    tile = texture_tile_size_cm("asanoha", 3.0)
    texture = kimono_texture(motif="asanoha", px_per_cm=64)
    garment = mesh.to_trimesh(texture=texture, texture_tile_cm=tile)
    with Renderer() as r:
        for view in ("front", "side"):
            path = write_png(out / f"body_{view}.png", r.render(body.mesh, view=view, size=size))
            result.files[path] = f"default body, {view} view"
        path = write_png(out / "kimono_on_stand.png", r.render([body.mesh, garment], view="front", size=size))
        result.files[path] = "kimono at its placement hint around the body (before wrapping)"
        step("render", t)

        t = time.perf_counter()
        dressed = dress_default_kimono(body)
        rep = dressed.report
        step("dress", t)
        t = time.perf_counter()
        result.files[
            write_garment_glb(dressed, out / "dressed.glb", body=body.mesh, texture=texture, tile_m=tile[0] / 100)
        ] = f"the kimono dressed on the body (strokes + wrap + settle, obi band held), {dressed.n_vertices} vertices"
        result.files[write_garment_obj(dressed, out / "dressed.obj")] = "dressed kimono, vt = pattern metres"
        verdict = "all quality targets met" if rep.ok else "targets missed: " + ", ".join(rep.failures())
        result.files[write_garment_report(dressed, out / "dressed_report.json")] = (
            f"quality: strain mean {100 * rep.strain_mean:.1f} % max {100 * rep.strain_max:.1f} %, "
            f"deepest {rep.penetration_deepest_mm:.1f} mm inside, seam gap {rep.seam_gap_mm:.1f} mm; {verdict}"
        )
        shown = garment_glb_mesh(dressed, tile_m=tile[0] / 100, texture=texture)
        sheet = render_sheet([body.mesh, shown], renderer=r, size=(size[0] // 2, size[1] // 2))
        result.files[write_png(out / "dressed.png", sheet)] = "dressed kimono, front / side / back"
        step("write", t)
    return result
