"""Offscreen rendering of triangle meshes with moderngl on a headless EGL context.

Creating the OpenGL context costs most of a second on Mesa llvmpipe, so a `Renderer` owns one context and is
reused; `render` (module level) uses a shared default Renderer.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path
from typing import Literal

import numpy as np

from .. import limits
from .._files import atomic_path, check_output, require_file
from ..errors import InputError
from ..geometry import TriMesh
from . import shaders
from .camera import Camera, View, frame_camera

ColorLike = str | Sequence[float]
"""A colour: a CSS name or ``#rrggbb`` string, or 3 (or 4) numbers in [0, 1] (sRGB)."""

#: Default sRGB colours: the first mesh (usually the body) gets a neutral clay skin, the others cloth colours.
BODY_COLOR = (0.80, 0.69, 0.61)
GARMENT_COLORS = ((0.25, 0.35, 0.58), (0.66, 0.22, 0.24), (0.35, 0.50, 0.38), (0.78, 0.63, 0.32))
#: Default background: a soft vertical gradient, top colour then bottom colour (sRGB).
BACKGROUND = ((0.96, 0.96, 0.97), (0.84, 0.85, 0.87))
DEFAULT_SIZE = (800, 1000)

_EGL_HINT = "install the Debian packages libegl1 libgl1-mesa-dri (EGL and Mesa's OpenGL drivers)"


def parse_color(color: ColorLike, *, what: str = "color") -> tuple[float, float, float]:
    """sRGB (r, g, b) floats in [0, 1] from a CSS name, a ``#rrggbb`` string or 3 (or 4) numbers in [0, 1]."""
    if isinstance(color, str):
        from PIL import ImageColor

        try:
            rgb = ImageColor.getrgb(color.strip())
        except ValueError:
            raise InputError(f"unknown {what} {color!r}; use a name like 'navy' or '#rrggbb'") from None
        return tuple(c / 255.0 for c in rgb[:3])  # type: ignore[return-value]
    c = np.asarray(color, dtype=np.float64).ravel()
    if c.shape not in ((3,), (4,)) or not np.all((c >= 0.0) & (c <= 1.0)):
        raise InputError(f"{what} must be 3 numbers in [0, 1], got {color!r}")
    return float(c[0]), float(c[1]), float(c[2])


def _linear(rgb: Sequence[float]) -> tuple[float, float, float]:
    return tuple(float(c) ** 2.2 for c in rgb)  # type: ignore[return-value]


def _check_mesh(mesh: TriMesh) -> None:
    label = f"mesh {mesh.name!r}"
    if mesh.n_vertices == 0 or mesh.n_faces == 0:
        raise InputError("is empty (no vertices or no faces), nothing to render", label)
    if not np.all(np.isfinite(mesh.vertices)):
        raise InputError("has NaN or infinite vertex coordinates", label)
    if mesh.faces.min() < 0 or mesh.faces.max() >= mesh.n_vertices:
        raise InputError(f"has face indices outside 0..{mesh.n_vertices - 1}", label)
    if mesh.texture is not None:
        if mesh.uv is None:
            raise InputError("has a texture but no uv coordinates to map it", label)
        t = mesh.texture
        if t.dtype != np.uint8 or t.ndim != 3 or t.shape[2] not in (3, 4) or min(t.shape[:2]) == 0:
            raise InputError(f"texture must be an (H, W, 3|4) uint8 image, got {t.dtype} {t.shape}", label)
        if not np.all(np.isfinite(mesh.uv)):
            raise InputError("has NaN or infinite uv coordinates", label)


class Renderer:
    """An offscreen OpenGL renderer: one EGL context, reused for any number of images.

    Raises InputError when no EGL/OpenGL driver can be opened. Use as a context manager or call `close()`.
    """

    def __init__(self) -> None:
        try:
            import moderngl
        except ImportError as e:  # pragma: no cover - moderngl is a declared dependency
            raise InputError(f"moderngl is not installed ({e}); pip install moderngl") from None
        try:
            self.ctx = moderngl.create_standalone_context(backend="egl")
        except Exception as e:  # noqa: BLE001 - glcontext raises bare Exceptions for every loader failure
            reason = " ".join(str(e).split()) or type(e).__name__  # one line, whatever the loader said
            raise InputError(f"no OpenGL/EGL for offscreen rendering ({reason}); {_EGL_HINT}") from None
        self._moderngl = moderngl
        self.program = self.ctx.program(vertex_shader=shaders.VERTEX, fragment_shader=shaders.FRAGMENT)
        self.background_program = self.ctx.program(
            vertex_shader=shaders.BACKGROUND_VERTEX, fragment_shader=shaders.BACKGROUND_FRAGMENT
        )
        self._background_vao = self.ctx.vertex_array(self.background_program, [])
        self.max_samples = int(self.ctx.max_samples)
        self.max_size = int(self.ctx.info.get("GL_MAX_RENDERBUFFER_SIZE", 4096))
        self._fbos: dict[tuple[int, int, int], tuple] = {}
        # textures kept across renders (a video draws the same garment texture every frame: its upload and
        # mipmaps cost about as much as the draw): id -> (the image, kept alive so the id stays its own; texture)
        self._textures: dict[int, tuple[np.ndarray, object]] = {}

    # -- lifecycle ------------------------------------------------------------------------------------------
    def close(self) -> None:
        for fbos in self._fbos.values():
            for obj in fbos:
                obj.release()
        self._fbos.clear()
        for _, texture in self._textures.values():
            texture.release()
        self._textures.clear()
        self.ctx.release()

    def __enter__(self) -> Renderer:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    @property
    def renderer_name(self) -> str:
        """The OpenGL driver, e.g. 'llvmpipe (LLVM 15.0.6, 256 bits)'."""
        return str(self.ctx.info["GL_RENDERER"])

    # -- rendering ------------------------------------------------------------------------------------------
    def render(
        self,
        meshes: TriMesh | Sequence[TriMesh],
        *,
        view: View | str = "front",
        camera: Camera | None = None,
        size: tuple[int, int] = DEFAULT_SIZE,
        colors: Sequence[ColorLike | None] | None = None,
        background: ColorLike | tuple[ColorLike, ColorLike] | None = BACKGROUND,
        wireframe: bool = False,
        shading: Literal["smooth", "flat"] = "smooth",
        samples: int = 4,
        supersample: int = 1,
        fov_y_deg: float = 30.0,
        margin: float = 0.05,
        occluders: Sequence[TriMesh] = (),
    ) -> np.ndarray:
        """Render meshes into an image.

        Parameters
        ----------
        meshes : one TriMesh or several (e.g. body then garment). A mesh with `uv` and `texture` is textured.
        view : a named view (see `kitsuke.render.camera`), auto-framed on all meshes; ignored with `camera`.
        camera : an explicit Camera instead of a named view.
        size : (width, height) pixels.
        colors : one sRGB colour per mesh (None entries or a short list fall back to the defaults: a clay skin
            tone for the first mesh, cloth colours for the others). Ignored for a textured mesh.
        background : a colour, a (top, bottom) pair of colours for a vertical gradient, or None for a
            transparent background (the result is then RGBA, straight alpha).
        wireframe : draw the triangle edges over the shading.
        shading : "smooth" (area-weighted vertex normals) or "flat" (face normals: boxes, low-poly meshes).
        samples : MSAA samples per pixel (clamped to what the driver offers; llvmpipe: 4).
        supersample : render at this many times the size and average down (more anti-aliasing; cost ~ square).
        fov_y_deg, margin : vertical field of view (degrees) and free border (fraction of the image) of the
            auto-framed views.
        occluders : meshes drawn into depth only, before the others: invisible, they hide what lies behind them
            (a body hiding the inside and back of a garment composited over a photo of the person).

        Returns
        -------
        (H, W, 3) uint8 RGB, or (H, W, 4) uint8 RGBA when `background` is None.
        """
        mesh_list = [meshes] if isinstance(meshes, TriMesh) else list(meshes)
        if not mesh_list:
            raise InputError("no meshes to render")
        hidden = list(occluders)
        for m in mesh_list + hidden:
            _check_mesh(m)
        width, height = _check_size(size, self.max_size, supersample, samples)
        if shading not in ("smooth", "flat"):
            raise InputError(f"shading must be 'smooth' or 'flat', got {shading!r}")
        mesh_colors = _mesh_colors(len(mesh_list), colors)
        if camera is None:
            all_vertices = np.concatenate([m.vertices for m in mesh_list])
            camera = frame_camera(all_vertices, view, aspect=width / height, fov_y_deg=fov_y_deg, margin=margin)
        gradient = _background_colors(background)
        ss_size = (width * supersample, height * supersample)
        image = self._draw(mesh_list, mesh_colors, camera, ss_size, wireframe, shading, samples, gradient, hidden)
        if supersample > 1:
            c = image.shape[2]
            blocks = image.reshape(height, supersample, width, supersample, c).astype(np.float32)
            image = np.rint(blocks.mean(axis=(1, 3))).astype(np.uint8)
        return image

    def _framebuffers(self, size: tuple[int, int], samples: int) -> tuple:
        key = (size[0], size[1], samples)
        if key not in self._fbos:
            ctx = self.ctx
            ms = samples if samples > 1 else 0  # 0 = a plain renderbuffer (1 would still be multisampled)
            color = ctx.renderbuffer(size, components=4, samples=ms)
            depth = ctx.depth_renderbuffer(size, samples=ms)
            msaa = ctx.framebuffer(color_attachments=[color], depth_attachment=depth)
            objs: tuple = (color, depth, msaa)
            if samples > 1:
                resolved_color = ctx.renderbuffer(size, components=4)
                resolved = ctx.framebuffer(color_attachments=[resolved_color])
                objs += (resolved_color, resolved)
            # Keep a few sizes around (a contact sheet renders several views at one size).
            if len(self._fbos) >= 4:
                for obj in self._fbos.pop(next(iter(self._fbos))):
                    obj.release()
            self._fbos[key] = objs
        return self._fbos[key]

    def _draw(
        self,
        meshes: list[TriMesh],
        colors: list[tuple[float, float, float]],
        camera: Camera,
        size: tuple[int, int],
        wireframe: bool,
        shading: str,
        samples: int,
        background: tuple[tuple[float, float, float], tuple[float, float, float]] | None,
        occluders: list[TriMesh],
    ) -> np.ndarray:
        """Draw into the (MSAA) framebuffer and read it back: (H, W, 3) uint8 RGB over the background, or
        (H, W, 4) straight-alpha RGBA on a transparent background (None); top row first."""
        moderngl, ctx, prog = self._moderngl, self.ctx, self.program
        samples = max(1, min(int(samples), self.max_samples))
        fbos = self._framebuffers(size, samples)
        fbo = fbos[2]
        fbo.use()
        ctx.viewport = (0, 0, *size)
        ctx.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
        ctx.disable(moderngl.DEPTH_TEST | moderngl.CULL_FACE | moderngl.BLEND)
        if background is not None:
            # Drawn on the GPU, under the meshes: the MSAA resolve then blends silhouette edges into it.
            self.background_program["u_top"].value = background[0]
            self.background_program["u_bottom"].value = background[1]
            self._background_vao.render(moderngl.TRIANGLES, vertices=3)
        ctx.enable(moderngl.DEPTH_TEST)

        near, far = camera.depth_range(np.concatenate([m.vertices for m in meshes + occluders]))
        view_proj = camera.projection_matrix(size[0] / size[1], near, far) @ camera.view_matrix()
        right, up, back = camera.basis()
        # Lights fixed to the camera: key from upper left and a little in front, fill from the right.
        key = right * -0.7 + up * 0.6 + back * 0.4
        fill = right * 0.75 + up * 0.05 + back * 0.45
        prog["u_view_proj"].write(view_proj.T.astype("f4").tobytes())  # GLSL matrices are column-major
        prog["u_eye"].value = tuple(camera.eye)
        prog["u_key_dir"].value = tuple(key / np.linalg.norm(key))
        prog["u_fill_dir"].value = tuple(fill / np.linalg.norm(fill))
        prog["u_flat"].value = shading == "flat"
        # Half-width of a wireframe line in pixels (it is drawn on both triangles of an edge): ~1 px lines.
        prog["u_wire_px"].value = 0.55 * max(1.0, min(size) / 1000.0) if wireframe else 0.0
        prog["u_unindexed"].value = wireframe
        prog["u_texture"].value = 0

        if occluders:
            fbo.color_mask = (False, False, False, False)
            fbo.use()  # moderngl applies a framebuffer's masks when it is bound
            for mesh in occluders:
                self._draw_mesh(mesh, unindexed=wireframe, shaded=False)
            fbo.color_mask = (True, True, True, True)
            fbo.use()
        for mesh, color in zip(meshes, colors, strict=True):
            prog["u_color"].value = _linear(color)
            self._draw_mesh(mesh, unindexed=wireframe)

        if samples > 1:
            ctx.copy_framebuffer(fbos[4], fbo)
            fbo = fbos[4]
        c = 3 if background is not None else 4
        data = fbo.read(components=c, dtype="f1")
        image = np.frombuffer(data, dtype=np.uint8).reshape(size[1], size[0], c)[::-1].copy()  # GL: bottom row first
        if background is None:
            _unpremultiply(image)
        return image

    def _draw_mesh(self, mesh: TriMesh, *, unindexed: bool, shaded: bool = True) -> None:
        """Upload one mesh, draw it with the program's current settings, and release it. shaded : False for a
        depth-only occluder (no normals to compute)."""
        resources = self._upload(mesh, unindexed=unindexed, normals=shaded)
        try:
            texture = self._texture(mesh.texture) if mesh.texture is not None else None
            self.program["u_textured"].value = texture is not None
            if texture is not None:
                texture.use(0)
            resources[0].render(self._moderngl.TRIANGLES)
        finally:
            for obj in resources:
                if obj is not None:
                    obj.release()

    def _texture(self, image: np.ndarray):  # noqa: ANN202 - a moderngl Texture
        """The GPU texture of an (H, W, 3|4) uint8 image, uploaded once per image (the same array object)."""
        key = id(image)
        if key in self._textures and self._textures[key][0] is image:
            return self._textures[key][1]
        if len(self._textures) >= 8:
            self._textures.pop(next(iter(self._textures)))[1].release()
        flipped = np.ascontiguousarray(image[::-1])  # uv v = 0 is the image's bottom row
        texture = self.ctx.texture(flipped.shape[1::-1], flipped.shape[2], flipped.tobytes())
        texture.build_mipmaps()
        texture.filter = (self._moderngl.LINEAR_MIPMAP_LINEAR, self._moderngl.LINEAR)
        # No anisotropic filtering: llvmpipe (the CPU renderer) does it in software, and a textured garment seen
        # edge-on took 77 s per view at 8x (0.3 s without).
        texture.anisotropy = 1.0
        texture.repeat_x = texture.repeat_y = True
        self._textures[key] = (image, texture)
        return texture

    def _upload(self, mesh: TriMesh, *, unindexed: bool, normals: bool = True) -> tuple:
        """Vertex array and buffers of one mesh: position, normal (zero unless `normals`), uv as float32."""
        ctx, prog = self.ctx, self.program
        normal = mesh.vertex_normals.astype(np.float32) if normals else np.zeros((mesh.n_vertices, 3), np.float32)
        uv = mesh.uv if mesh.uv is not None else np.zeros((mesh.n_vertices, 2))
        data = np.concatenate([mesh.vertices.astype(np.float32), normal, uv.astype(np.float32)], axis=1)
        faces = mesh.faces.astype(np.int32)
        if unindexed:
            # Three vertices per triangle so the shader can number the corners (wireframe).
            vbo = ctx.buffer(np.ascontiguousarray(data[faces.ravel()]).tobytes())
            ibo = None
        else:
            vbo = ctx.buffer(np.ascontiguousarray(data).tobytes())
            ibo = ctx.buffer(np.ascontiguousarray(faces).tobytes())
        vao = ctx.vertex_array(
            prog,
            [(vbo, "3f 3f 2f", "in_position", "in_normal", "in_uv")],
            index_buffer=ibo,
            index_element_size=4,
        )
        return vao, vbo, ibo


def _check_size(size: tuple[int, int], max_size: int, supersample: int = 1, samples: int = 1) -> tuple[int, int]:
    try:
        width, height = (int(s) for s in size)
    except (TypeError, ValueError):
        raise InputError(f"size must be (width, height) in pixels, got {size!r}") from None
    if isinstance(samples, bool) or not isinstance(samples, int) or not 0 <= samples <= 64:
        raise InputError(f"samples must be an integer 0..64 (MSAA samples per pixel), got {samples!r}")
    if isinstance(supersample, bool) or not isinstance(supersample, int) or not 1 <= supersample <= 4:
        raise InputError(f"supersample must be an integer 1..4, got {supersample!r}")
    if width < 1 or height < 1 or max(width, height) * supersample > max_size:
        raise InputError(f"size {width}x{height} (x{supersample} supersampling) must be within 1..{max_size} px")
    return width, height


def _mesh_colors(n: int, colors: Sequence[ColorLike | None] | None) -> list[tuple[float, float, float]]:
    if colors is not None and (isinstance(colors, str) or len(colors) > n):
        if isinstance(colors, str):
            raise InputError("colors must be a list with one colour per mesh, not a single string")
        raise InputError(f"{len(colors)} colours given for {n} meshes")
    out = []
    for i in range(n):
        c = colors[i] if colors is not None and i < len(colors) else None
        if c is None:
            out.append(BODY_COLOR if i == 0 else GARMENT_COLORS[(i - 1) % len(GARMENT_COLORS)])
        else:
            out.append(parse_color(c))
    return out


def _background_colors(
    background: ColorLike | tuple[ColorLike, ColorLike] | None,
) -> tuple[tuple[float, float, float], tuple[float, float, float]] | None:
    """(top, bottom) sRGB colours of the background, or None for transparent."""
    if background is None:
        return None
    if isinstance(background, tuple | list) and len(background) == 2:
        return parse_color(background[0], what="background"), parse_color(background[1], what="background")
    c = parse_color(background, what="background")  # type: ignore[arg-type]
    return c, c


def _unpremultiply(rgba: np.ndarray) -> None:
    """In place: resolved MSAA holds colour x coverage at silhouette edges; PNG wants straight alpha."""
    alpha = rgba[..., 3]
    edge = (alpha > 0) & (alpha < 255)
    a = alpha[edge].astype(np.float32)[:, None]
    rgba[..., :3][edge] = np.clip(np.rint(rgba[..., :3][edge] * (255.0 / a)), 0, 255).astype(np.uint8)


_default: Renderer | None = None


def default_renderer() -> Renderer:
    """The process-wide shared Renderer (created on first use)."""
    global _default
    if _default is None:
        _default = Renderer()
    return _default


def render(meshes: TriMesh | Sequence[TriMesh], **options: object) -> np.ndarray:
    """Render with the shared default Renderer; options as in `Renderer.render`."""
    return default_renderer().render(meshes, **options)  # type: ignore[arg-type]


def read_texture(path: str | os.PathLike[str]) -> np.ndarray:
    """(H, W, 3|4) uint8 image from a PNG/JPEG/... file (RGBA if it has alpha); InputError naming the file."""
    from PIL import Image, UnidentifiedImageError

    p = require_file(path, what="texture image")
    try:
        with Image.open(p) as im:
            w, h = im.size
            limits.check_image(w, h, p)
            im = im.convert("RGBA" if im.mode in ("RGBA", "LA", "PA") else "RGB")
            return np.asarray(im, dtype=np.uint8)
    except InputError:
        raise
    except (UnidentifiedImageError, OSError, Image.DecompressionBombError, ValueError, SyntaxError) as e:
        # Pillow's decoders raise these for corrupt data (SyntaxError for some broken headers).
        raise InputError(f"not a readable image ({e.__class__.__name__})", p) from None


def write_png(
    path: str | os.PathLike[str], image: np.ndarray, *, inputs: Sequence[str | os.PathLike[str]] = ()
) -> Path:
    """Write an (H, W, 3|4) uint8 image as PNG atomically; refuses to overwrite any of `inputs`."""
    from PIL import Image

    image = np.asarray(image)
    if image.dtype != np.uint8 or image.ndim != 3 or image.shape[2] not in (3, 4):
        raise InputError(f"image must be (H, W, 3|4) uint8, got {image.dtype} {image.shape}", path)
    out = check_output(path, inputs)
    with atomic_path(out) as tmp:
        Image.fromarray(image).save(tmp, format="PNG")
    return out
