"""What a simulated kimono is written as: an animated GLB (the skinned body and the kimono, one morph target per
frame), an H.264 render of it, a picture strip, and the per-frame report."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from .._files import write_json_atomic
from ..geometry import TriMesh
from .simulate import KimonoMotion

#: The asanoha repeat the kimono is drawn with, cm (as in `kitsuke demo`).
TEXTURE_REPEAT_CM = 3.0


def kimono_template(garment, *, textured: bool = True) -> tuple[TriMesh, np.ndarray]:  # noqa: ANN001
    """A dressed kimono as viewers see it (vertices split at seams, asanoha texture on the pattern's uv), and
    (V',) the cloth vertex of each of its vertices: `mesh.vertices = positions[index]` poses it."""
    from ..dressing.export import as_garment_file, viewer_vertices
    from ..pattern import kimono_texture, texture_tile_size_cm

    index, faces, uv = viewer_vertices(garment)
    tile_m = texture_tile_size_cm("asanoha", TEXTURE_REPEAT_CM)[0] / 100
    texture = kimono_texture(motif="asanoha", repeat_cm=TEXTURE_REPEAT_CM, px_per_cm=64) if textured else None
    positions = np.asarray(as_garment_file(garment).positions, dtype=np.float64)[index]
    return TriMesh(positions, faces, uv / tile_m, name="kimono", texture=texture), index


def kimono_mesh(motion: KimonoMotion, frame: int = 0, *, textured: bool = True) -> tuple[TriMesh, np.ndarray]:
    """The kimono at `frame` as viewers see it (`kimono_template`), and (V',) the simulated vertex of each of its
    vertices."""
    mesh, index = kimono_template(motion.garment, textured=textured)
    return TriMesh(
        motion.positions[frame].astype(np.float64)[index], mesh.faces, mesh.uv, name="kimono", texture=mesh.texture
    ), index


def write_kimono_glb(motion: KimonoMotion, body, path: str | os.PathLike[str]) -> Path:  # noqa: ANN001 - Body
    """The body skinned and animated, and the kimono moving with it (morph targets), in one GLB."""
    from ..body.gltf_animation import MorphMesh, write_animated_glb

    mesh, index = kimono_mesh(motion)
    return write_animated_glb(body, motion.animation, path, MorphMesh(mesh, motion.positions[:, index]))


def _frame_meshes(motion: KimonoMotion, body, f: int, kimono: TriMesh, index: np.ndarray) -> list[TriMesh]:  # noqa: ANN001
    from ..body.animate import posed_vertices

    skin = TriMesh(posed_vertices(body, motion.animation, f), body.mesh.faces, name="body")
    cloth = TriMesh(motion.positions[f].astype(np.float64)[index], kimono.faces, kimono.uv, texture=kimono.texture)
    return [skin, cloth]


def _camera(motion: KimonoMotion, size: tuple[int, int], view: str):  # noqa: ANN202
    """One camera for the whole clip, framed on everything the body and kimono sweep through."""
    from ..render import frame_camera

    joints = motion.animation.joints.reshape(-1, 3)
    pts = np.concatenate([joints, motion.positions[:: max(1, len(motion.positions) // 20)].reshape(-1, 3)])
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    box = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
    return frame_camera(box, view, aspect=size[0] / size[1])


def write_kimono_video(
    motion: KimonoMotion,
    body,  # noqa: ANN001
    path: str | os.PathLike[str],
    *,
    size: tuple[int, int] = (640, 800),
    view: str = "front",
    progress: bool | None = None,
) -> Path:
    """An H.264 mp4 of the kimono on the moving body, one camera for the clip, with the time and each frame's
    strain and penetration written in a corner."""
    from PIL import Image, ImageDraw

    from .._progress import progress as bar
    from ..render import Renderer
    from ..render.video import mp4_writer

    size = (size[0] // 2 * 2, size[1] // 2 * 2)
    kimono, index = kimono_mesh(motion)
    camera = _camera(motion, size, view)
    with Renderer() as r, mp4_writer(path, size, motion.animation.fps) as send:
        for f in bar(range(len(motion.quality)), total=len(motion.quality), desc="video", enabled=progress):
            image = r.render(_frame_meshes(motion, body, f, kimono, index), camera=camera, size=size)
            q = motion.quality[f]
            label = "lead-in" if q.lead_in else f"t={q.time_s:.2f}s"
            label += f"  strain {100 * q.strain_max:.0f}%  inside>5mm {q.penetration_count}"
            pil = Image.fromarray(image)
            ImageDraw.Draw(pil).text((10, size[1] - 22), label, fill=(40, 40, 48))
            send(np.asarray(pil))
    return Path(path)


def picture_strip(
    motion: KimonoMotion,
    body,  # noqa: ANN001
    n: int = 6,
    *,
    size: tuple[int, int] = (240, 360),
    view: str = "front",
) -> np.ndarray:
    """(H, W, 3) uint8: `n` frames of the clip (the lead-in left out) side by side, labelled with their time."""
    from ..render import Renderer, contact_sheet

    start = motion.n_lead if motion.n_lead < len(motion.quality) else 0
    frames = np.unique(np.linspace(start, len(motion.quality) - 1, n).round().astype(int))
    kimono, index = kimono_mesh(motion)
    camera = _camera(motion, size, view)
    with Renderer() as r:
        images = [
            r.render(_frame_meshes(motion, body, int(f), kimono, index), camera=camera, size=size) for f in frames
        ]
    return contact_sheet(images, [f"t={motion.quality[int(f)].time_s:.2f}s" for f in frames])


def write_motion_report(motion: KimonoMotion, path: str | os.PathLike[str], **extra) -> Path:  # noqa: ANN003
    """The simulation's summary and per-frame measures (`KimonoMotion.summary`) as JSON, with `extra` keys first."""
    return write_json_atomic(path, {**extra, **motion.summary()})
