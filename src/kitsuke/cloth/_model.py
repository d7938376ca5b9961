"""The cloth's static model (topology, rest shape, parameters) apart from its changing state (positions, pins,
contacts).

A garment mesh shares the vertices of a seam between its two pieces, so a vertex has no single 2D pattern position.
The rest shape is therefore stored per triangle corner: `rest_corners (F, 3, 2)`, the pattern position of each
corner in metres, in its own piece's coordinates. Everything else (edge rest lengths, rest areas) derives from it.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass, field, fields

import numpy as np

from ..errors import InputError
from ..geometry.validate import edge_topology


@dataclass(frozen=True)
class ClothParams:
    """Every constant of the relaxation and the collision, with its unit and why it has its value.

    Stiffnesses are fractions of a full correction applied per iteration (Jacobi averaging), not physical moduli.
    """

    #: Fraction of the averaged shape-matching correction applied per iteration. 1 moves each vertex to the mean of
    #: its triangles' best-fit rest shapes; above 1 over-relaxes: 1.5 removes stretch 2-3 times faster than 1 on
    #: our tests and stays stable (1.9 and above diverge).
    stretch_stiffness: float = 1.5
    #: Fraction of the averaged hinge-flattening correction applied per iteration: how strongly folds open
    #: towards 180°. Small, so that cloth can still drape around the body.
    bend_stiffness: float = 0.05
    #: Downward move per iteration, metres (the "small move towards the ground" of the paper).
    gravity_step_m: float = 2e-4
    #: Coulomb friction coefficient for vertices touching the body: a move that presses into the body by dn loses
    #: up to friction * dn of its part along the body, so cloth pressed on the body (by its weight or by being
    #: stretched around it) stays put; moving off the body is free.
    friction: float = 0.6
    #: Largest move of a vertex in one iteration, metres: a safety clamp against explosions from bad input.
    max_step_m: float = 0.005
    #: Open triangles that are folded over their neighbours (the paper's automatic un-flipping; not physical).
    unflip: bool = True
    #: Strain limit: after each iteration, visiting the supports (pins, and vertices resting on body surfaces that
    #: face up) first and then the other vertices from the top down, every edge is shortened to at most (1 + this)
    #: times its rest length by moving its later end, so that hanging cloth does not stretch under the
    #: accumulated gravity moves (Jacobi averaging alone lets them stretch a chain in proportion to its length).
    #: Applied only with gravity on (gravity_step_m > 0); None disables it.
    max_stretch: float | None = 0.005
    #: A vertex touching the body supports hanging cloth when the body normal there points up at least this much
    #: (its y component; 0.5 = surfaces within 60 degrees of horizontal: shoulders, the top of the head, a hip's
    #: upper slope). On steeper surfaces the cloth hangs from what is above instead.
    support_normal_y: float = 0.5
    #: Distance the cloth is kept outside the body surface, metres. Also the depth of cloth considered "inside".
    contact_offset_m: float = 0.001
    #: A vertex closer to the body than this (metres) touches it: friction applies, and it supports hanging cloth.
    contact_distance_m: float = 0.006
    #: Below this distance to the body (metres) the incremental nearest-point walk is trusted; above it a global
    #: re-search is done only when the vertex may have come within contact distance since its last global search.
    track_distance_m: float = 0.03
    #: Steps of the nearest-point walk before it counts as failed (then a global AABB search is done).
    walk_max_steps: int = 64
    #: Push cloth edges (not only vertices) out of the body's capsules ("bones").
    edge_capsules: bool = True
    #: Layered cloth (`ClothModel.face_layer`): the distance kept between two layers, metres (a kimono's silk is
    #: ~0.3 mm thick; 2 mm keeps the outer layer's triangles clear of the inner one's vertices between them).
    layer_gap_m: float = 0.002
    #: Layered cloth: a vertex this close (metres) to another layer's face keeps the order against it. Farther
    #: apart, nothing is known about which layer is where (a kimono's two fronts hang apart below the obi).
    layer_reach_m: float = 0.02

    def __post_init__(self) -> None:
        for f in fields(self):
            v = getattr(self, f.name)
            if isinstance(v, bool) or v is None or f.name == "support_normal_y":
                continue
            if not np.isfinite(v) or v < 0:
                raise InputError(f"cloth parameter {f.name} must be a finite number >= 0, got {v!r}")
        if self.stretch_stiffness > 1.9:
            raise InputError("cloth parameter stretch_stiffness above 1.9 diverges")
        if self.contact_distance_m < self.contact_offset_m:
            raise InputError("cloth parameter contact_distance_m must be >= contact_offset_m")
        if not -1.0 <= self.support_normal_y <= 1.0:
            raise InputError(f"cloth parameter support_normal_y must be in [-1, 1], got {self.support_normal_y}")
        if self.walk_max_steps < 1:
            raise InputError("cloth parameter walk_max_steps must be >= 1")


#: Highest cloth layer (`ClothModel.face_layer`; a vertex's layers are bits of an int64).
MAX_LAYER = 62


def _csr(keys: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Group the positions of `keys` (m,) by key value in [0, n): (ptr (n + 1,), idx (m,)) int64."""
    order = np.argsort(keys, kind="stable").astype(np.int64)
    ptr = np.zeros(n + 1, dtype=np.int64)
    np.cumsum(np.bincount(keys, minlength=n), out=ptr[1:])
    return ptr, order


@dataclass(eq=False)
class ClothModel:
    """Static cloth data: topology and rest shape. Build with `ClothModel.from_corners` or `from_flat`.

    Attributes
    ----------
    faces : (F, 3) int64, vertex indices; the winding gives each triangle's outer side (pattern front face).
    rest_corners : (F, 3, 2) float64, metres: the pattern position of each corner in its piece's coordinates,
        reflected where needed so that every rest triangle is counter-clockwise in face order (the reflection keeps
        all lengths and angles; it only says which side is out).
    rest_areas : (F,) float64, square metres.
    edges : (E, 2) int64, unique undirected edges, sorted pairs in lexicographic order (the order of
        `kitsuke.metrics.mesh_edges`).
    rest_lengths : (E,) float64, metres: from the rest corners (mean of the two triangles' lengths on a seam).
    edge_faces : (E, 2) int64, the faces on either side (-1 where the edge is on the boundary).
    seam_edges : (E,) bool, interior edges whose two triangles disagree on the rest position of the shared
        vertices (the edge is a seam between two pieces, or between two edges of one piece).
    face_adjacency : (F, 3) int64, the face across local edge k (corners k, k+1), -1 on the boundary.
    face_adjacency_sign : (F, 3) float64, +1 where that neighbour is wound consistently, -1 where not.
    hinges : (H, 4) int64, per interior edge: its two vertices a, b (in the order of the first face) and the
        opposite vertices c (first face) and d (second face) — the dihedral edge pairs.
    hinge_faces : (H, 2) int64, the two faces of each hinge.
    vertex_corners_ptr, vertex_corners : CSR (V + 1,), (3F,) int64: the corners (face * 3 + k) at each vertex.
    vertex_hinges_ptr, vertex_hinges : CSR (V + 1,), (4H,) int64: the hinge slots (hinge * 4 + slot) at each vertex.
    adjacency_ptr, adjacency, adjacency_edge : CSR (V + 1,), (2E,), (2E,) int64: each vertex's neighbours and the
        edge joining them.
    boundary_vertices : (V,) bool, on a boundary edge.
    params : ClothParams.
    face_layer : (F,) int8 (0..MAX_LAYER) or None: layered cloth (SPEC §5.4, a kimono's left front over its
        right). 0 for faces outside any layer; where faces of two different layers meet, the higher layer is kept
        outside the lower one (`collide`).
    vertex_layer : (V,) int8, a vertex's layer where all its faces share one, else 0.
        layer_faces, layer_vertices : int64 indices of the faces and vertices with a layer (empty without);
        layer_face_vertices : the vertices of layer_faces; layers_at : (V,) int64, bit l set where a vertex has
        a face of layer l; layer_cell_m : the grid cell of `keep_layers`, metres.
    """

    faces: np.ndarray
    rest_corners: np.ndarray
    params: ClothParams = field(default_factory=ClothParams)
    n_vertices: int = 0
    face_layer: np.ndarray | None = None
    rest_areas: np.ndarray = field(init=False, repr=False)
    edges: np.ndarray = field(init=False, repr=False)
    rest_lengths: np.ndarray = field(init=False, repr=False)
    edge_faces: np.ndarray = field(init=False, repr=False)
    seam_edges: np.ndarray = field(init=False, repr=False)
    face_adjacency: np.ndarray = field(init=False, repr=False)
    face_adjacency_sign: np.ndarray = field(init=False, repr=False)
    hinges: np.ndarray = field(init=False, repr=False)
    hinge_faces: np.ndarray = field(init=False, repr=False)
    vertex_corners_ptr: np.ndarray = field(init=False, repr=False)
    vertex_corners: np.ndarray = field(init=False, repr=False)
    vertex_hinges_ptr: np.ndarray = field(init=False, repr=False)
    vertex_hinges: np.ndarray = field(init=False, repr=False)
    adjacency_ptr: np.ndarray = field(init=False, repr=False)
    adjacency: np.ndarray = field(init=False, repr=False)
    adjacency_edge: np.ndarray = field(init=False, repr=False)
    boundary_vertices: np.ndarray = field(init=False, repr=False)
    vertex_layer: np.ndarray = field(init=False, repr=False)
    layer_faces: np.ndarray = field(init=False, repr=False)
    layer_vertices: np.ndarray = field(init=False, repr=False)
    layer_face_vertices: np.ndarray = field(init=False, repr=False)
    layers_at: np.ndarray = field(init=False, repr=False)
    layer_cell_m: float = field(init=False, repr=False)

    @classmethod
    def from_corners(
        cls,
        faces: np.ndarray,
        rest_corners: np.ndarray,
        *,
        n_vertices: int | None = None,
        params: ClothParams | None = None,
        face_layer: np.ndarray | None = None,
    ) -> ClothModel:
        """Model from faces (F, 3) and per-corner pattern positions (F, 3, 2) in metres.

        n_vertices : number of vertices (default: the largest index + 1).
        face_layer : (F,) integers 0..127 or None, see the class docstring.
        Raises InputError for malformed arrays, a degenerate rest triangle or a non-manifold edge.
        """
        faces = _as_faces(faces)
        rc = np.asarray(rest_corners, dtype=np.float64)
        if rc.shape != (len(faces), 3, 2):
            raise InputError(f"rest_corners must have shape ({len(faces)}, 3, 2), got {rc.shape}")
        if not np.isfinite(rc).all():
            raise InputError("rest_corners hold NaN or infinity")
        n = int(faces.max()) + 1 if n_vertices is None else int(n_vertices)
        if n <= faces.max():
            raise InputError(f"a face refers to vertex {int(faces.max())} but there are {n} vertices")
        return cls(faces, np.ascontiguousarray(rc), params or ClothParams(), n, face_layer)

    @classmethod
    def from_flat(cls, faces: np.ndarray, rest_uv: np.ndarray, *, params: ClothParams | None = None) -> ClothModel:
        """Model from faces (F, 3) and one pattern position per vertex, rest_uv (V, 2) metres (no shared seams)."""
        faces = _as_faces(faces)
        uv = np.asarray(rest_uv, dtype=np.float64)
        if uv.ndim != 2 or uv.shape[1] != 2:
            raise InputError(f"rest_uv must have shape (V, 2), got {uv.shape}")
        if faces.max() >= len(uv):
            raise InputError(f"a face refers to vertex {int(faces.max())} but rest_uv has {len(uv)} rows")
        return cls.from_corners(faces, uv[faces], n_vertices=len(uv), params=params)

    def __post_init__(self) -> None:
        self.faces = _as_faces(self.faces)
        f, nv = self.faces, max(self.n_vertices, int(self.faces.max()) + 1)
        self.n_vertices = nv
        rc = np.array(self.rest_corners, dtype=np.float64)
        e1, e2 = rc[:, 1] - rc[:, 0], rc[:, 2] - rc[:, 0]
        signed = 0.5 * (e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])
        scale = np.maximum(np.einsum("ij,ij->i", e1, e1), np.einsum("ij,ij->i", e2, e2))
        bad = np.abs(signed) <= 1e-9 * scale
        if bad.any():
            raise InputError(
                f"{int(bad.sum())} rest triangles are degenerate (zero area), e.g. face {int(bad.argmax())}"
            )
        rc[signed < 0, :, 0] *= -1.0  # reflect clockwise rest triangles: same lengths, counter-clockwise in face order
        self.rest_corners = np.ascontiguousarray(rc)
        self.rest_areas = np.abs(signed)

        nf = len(f)
        he_from = f.reshape(-1)  # half-edge (f, k) runs corner k -> k + 1
        he_to = f[:, [1, 2, 0]].reshape(-1)
        edges, counts = edge_topology(f)
        if (counts > 2).any():
            raise InputError(f"{int((counts > 2).sum())} cloth edges are shared by more than two triangles")
        lo, hi = np.minimum(he_from, he_to), np.maximum(he_from, he_to)
        he_edge = np.searchsorted(edges[:, 0] * nv + edges[:, 1], lo * nv + hi)
        self.edges = edges
        ne = len(edges)
        rc_to = self.rest_corners[:, [1, 2, 0]].reshape(-1, 2)
        he_len = np.linalg.norm(rc_to - self.rest_corners.reshape(-1, 2), axis=1)
        self.rest_lengths = np.bincount(he_edge, he_len, ne) / counts

        # The (up to) two half-edges of each edge, first and second in half-edge order.
        order = np.argsort(he_edge, kind="stable")
        first = np.full(ne, -1, dtype=np.int64)
        second = np.full(ne, -1, dtype=np.int64)
        starts = np.searchsorted(he_edge[order], np.arange(ne))
        first[:] = order[starts]
        two = counts == 2
        second[two] = order[starts[two] + 1]
        self.edge_faces = np.stack([first // 3, np.where(second >= 0, second // 3, -1)], axis=1)

        adj = np.full(3 * nf, -1, dtype=np.int64)
        sign = np.ones(3 * nf)
        h1, h2 = first[two], second[two]
        adj[h1], adj[h2] = h2 // 3, h1 // 3
        consistent = he_from[h1] == he_to[h2]
        sign[h1] = sign[h2] = np.where(consistent, 1.0, -1.0)
        self.face_adjacency = adj.reshape(nf, 3)
        self.face_adjacency_sign = sign.reshape(nf, 3)

        # Seams: the two triangles place the shared vertices at different pattern positions.
        rc_flat = self.rest_corners.reshape(-1, 2)

        def corner_of(h: np.ndarray, v: np.ndarray) -> np.ndarray:
            fa, k = h // 3, h % 3
            return np.where(f[fa, k] == v, fa * 3 + k, fa * 3 + (k + 1) % 3)

        ea, eb = edges[two, 0], edges[two, 1]
        tol = 1e-7 + 1e-6 * self.rest_lengths[two]
        differ = (np.linalg.norm(rc_flat[corner_of(h1, ea)] - rc_flat[corner_of(h2, ea)], axis=1) > tol) | (
            np.linalg.norm(rc_flat[corner_of(h1, eb)] - rc_flat[corner_of(h2, eb)], axis=1) > tol
        )
        self.seam_edges = np.zeros(ne, dtype=bool)
        self.seam_edges[np.flatnonzero(two)] = differ

        k1 = h1 % 3
        fa1, fa2 = h1 // 3, h2 // 3
        a, b = f[fa1, k1], f[fa1, (k1 + 1) % 3]
        c = f[fa1, (k1 + 2) % 3]
        d = f[fa2, (h2 % 3 + 2) % 3]
        self.hinges = np.ascontiguousarray(np.stack([a, b, c, d], axis=1), dtype=np.int64)
        self.hinge_faces = np.ascontiguousarray(np.stack([fa1, fa2], axis=1), dtype=np.int64)

        self.vertex_corners_ptr, self.vertex_corners = _csr(f.reshape(-1), nv)
        self.vertex_hinges_ptr, self.vertex_hinges = _csr(self.hinges.reshape(-1), nv)
        both = np.concatenate([edges, edges[:, ::-1]])
        idx = np.lexsort((both[:, 1], both[:, 0]))  # by vertex, then by neighbour
        ptr = np.zeros(nv + 1, dtype=np.int64)
        np.cumsum(np.bincount(both[:, 0], minlength=nv), out=ptr[1:])
        self.adjacency_ptr = ptr
        self.adjacency = np.ascontiguousarray(both[idx, 1])
        self.adjacency_edge = np.ascontiguousarray(np.concatenate([np.arange(ne), np.arange(ne)])[idx])
        self.boundary_vertices = np.zeros(nv, dtype=bool)
        self.boundary_vertices[edges[~two].reshape(-1)] = True
        self._layers()

    def _layers(self) -> None:
        nf, nv = len(self.faces), self.n_vertices
        self.vertex_layer = np.zeros(nv, dtype=np.int8)
        if self.face_layer is None or not np.any(self.face_layer):
            self.face_layer = None
            self.layer_faces = self.layer_vertices = self.layer_face_vertices = np.zeros(0, dtype=np.int64)
            self.layers_at = np.zeros(nv, dtype=np.int64)
            self.layer_cell_m = 0.0
            return
        fl = np.asarray(self.face_layer)
        if fl.shape != (nf,) or not np.issubdtype(fl.dtype, np.integer) or fl.min() < 0 or fl.max() > MAX_LAYER:
            raise InputError(f"face_layer must be ({nf},) integers in 0..{MAX_LAYER}, got {fl.shape} {fl.dtype}")
        self.face_layer = np.ascontiguousarray(fl, dtype=np.int8)
        corner_layer = np.repeat(self.face_layer.astype(np.int64), 3)
        lo = np.full(nv, MAX_LAYER + 1, dtype=np.int64)
        hi = np.zeros(nv, dtype=np.int64)
        np.minimum.at(lo, self.faces.reshape(-1), corner_layer)
        np.maximum.at(hi, self.faces.reshape(-1), corner_layer)
        self.vertex_layer[lo == hi] = hi[lo == hi]
        self.layer_faces = np.flatnonzero(self.face_layer)
        self.layer_vertices = np.flatnonzero(self.vertex_layer)
        self.layers_at = np.zeros(nv, dtype=np.int64)
        np.bitwise_or.at(self.layers_at, self.faces.reshape(-1), np.left_shift(1, corner_layer) * (corner_layer > 0))
        self.layer_face_vertices = np.unique(self.faces[self.layer_faces])
        self.layer_cell_m = self._layer_cell_m()

    def _layer_cell_m(self) -> float:
        """Grid cells for `keep_layers`: the nearest point of a face within reach has a corner within reach plus
        most of an edge."""
        return self.params.layer_reach_m + 0.6 * float(np.median(self.rest_lengths))

    @property
    def n_faces(self) -> int:
        return len(self.faces)

    @property
    def n_edges(self) -> int:
        return len(self.edges)

    def with_params(self, params: ClothParams) -> ClothModel:
        """The same cloth with other parameters. The topology arrays are shared, not rebuilt (nothing changes
        them in place): rebuilding took 10 ms on GarmentCode's shirt, three times in every wrap."""
        if not isinstance(params, ClothParams):
            raise InputError("with_params needs a ClothParams")
        model = copy.copy(self)
        model.params = params
        if model.face_layer is not None:
            model.layer_cell_m = model._layer_cell_m()
        return model


def _as_faces(faces: np.ndarray) -> np.ndarray:
    f = np.asarray(faces)
    if f.ndim != 2 or f.shape[1] != 3 or len(f) == 0:
        raise InputError(f"faces must have shape (F, 3) with F > 0, got {f.shape}")
    if not np.issubdtype(f.dtype, np.integer):
        raise InputError("faces must be integer vertex indices")
    if f.min() < 0:
        raise InputError("faces hold a negative vertex index")
    if ((f[:, 0] == f[:, 1]) | (f[:, 1] == f[:, 2]) | (f[:, 2] == f[:, 0])).any():
        raise InputError("a face repeats a vertex")
    return np.ascontiguousarray(f, dtype=np.int64)


@dataclass
class Contacts:
    """Each cloth vertex's tracked nearest body-surface point (Skin-style), refreshed by the collision update.

    face : (V,) int64, body face of the nearest point; -1 = not tracked yet (a global search will find it).
    bary : (V, 3) float64, barycentric coordinates of the nearest point in that face.
    point : (V, 3) float64, metres, the nearest body point.
    normal : (V, 3) float64, unit body normal there, interpolated from the vertex normals (push-out direction).
    distance : (V,) float64, metres, signed distance to the body (negative inside).
    anchor : (V, 3) float64, metres, where the vertex was at its last trusted nearest-point result.
    anchor_distance : (V,) float64, metres, its distance to the body then (a lower bound on later distances, less
        the distance moved since).
    """

    face: np.ndarray
    bary: np.ndarray
    point: np.ndarray
    normal: np.ndarray
    distance: np.ndarray
    anchor: np.ndarray
    anchor_distance: np.ndarray

    @classmethod
    def empty(cls, n: int) -> Contacts:
        return cls(
            np.full(n, -1, dtype=np.int64),
            np.zeros((n, 3)),
            np.zeros((n, 3)),
            np.zeros((n, 3)),
            np.full(n, np.inf),
            np.zeros((n, 3)),
            np.full(n, np.inf),
        )

    def forget_anchors(self) -> None:
        """Forget the lower bounds on far vertices' distances (call after the body moved): far vertices get a
        global search at the next update instead of trusting that they cannot have come near."""
        self.anchor_distance[:] = -np.inf

    def forget(self) -> None:
        """Forget every tracked point: the next update searches all vertices globally. The walk of the tracking
        follows the distance downhill from the last face, so where two body surfaces are close (an armpit: arm
        and torso) a vertex pushed through one of them can stay tracked to the other, outside it; a global search
        finds the true nearest point (measured on GarmentCode's shirt after the wrap's close: 9 vertices 2-4 mm
        inside the torso, all tracked to the arm; after `forget` and one collision update, none). The wrap calls
        it before its edge-length restoration and the global settle at its end."""
        self.face[:] = -1
        self.distance[:] = np.inf
        self.anchor_distance[:] = np.inf

    def assign(self, other: Contacts) -> None:
        """Take `other`'s tracked points (in place, so that states sharing these contacts see them)."""
        for f in fields(self):
            getattr(self, f.name)[...] = getattr(other, f.name)

    def touching(self, contact_distance_m: float) -> np.ndarray:
        """(V,) bool: tracked and closer to the body than `contact_distance_m`."""
        return (self.face >= 0) & (self.distance < contact_distance_m)

    def take(self, index: np.ndarray) -> Contacts:
        """Contacts of the vertices `index` (an index array; -1 entries become untracked)."""
        idx = np.asarray(index, dtype=np.int64)
        new = idx < 0
        src = np.where(new, 0, idx)
        c = Contacts(*(np.array(getattr(self, f.name)[src]) for f in fields(self)))
        c.face[new] = -1
        c.distance[new] = np.inf
        c.anchor_distance[new] = np.inf
        return c


@dataclass(eq=False)
class ClothState:
    """What changes while the cloth relaxes.

    positions : (V, 3) float64, metres, world frame (Y up).
    pinned : (V,) bool, vertices held where they are.
    face_active : (F,) bool, triangles taking part (the wrap grows the garment by activating triangles). A vertex
        with no active triangle does not move.
    contacts : Contacts, the body tracking.
    velocities : (V, 3) float64 m/s for the dynamic solver (`kitsuke.cloth.step`), None until it starts.
    """

    positions: np.ndarray
    pinned: np.ndarray
    face_active: np.ndarray
    contacts: Contacts
    velocities: np.ndarray | None = None
    _work: dict = field(default_factory=dict, repr=False)

    @classmethod
    def new(
        cls,
        model: ClothModel,
        positions: np.ndarray,
        *,
        pinned: np.ndarray | None = None,
        face_active: np.ndarray | None = None,
    ) -> ClothState:
        """State of `model` at `positions` (V, 3) metres; pinned (V,) bool and face_active (F,) bool optional."""
        pos = np.asarray(positions, dtype=np.float64)
        if pos.shape != (model.n_vertices, 3):
            raise InputError(f"positions must have shape ({model.n_vertices}, 3), got {pos.shape}")
        if not np.isfinite(pos).all():
            raise InputError("positions hold NaN or infinity")
        pins = np.zeros(model.n_vertices, dtype=bool) if pinned is None else np.asarray(pinned, dtype=bool)
        if pins.shape != (model.n_vertices,):
            raise InputError(f"pinned must have shape ({model.n_vertices},), got {pins.shape}")
        act = np.ones(model.n_faces, dtype=bool) if face_active is None else np.asarray(face_active, dtype=bool)
        if act.shape != (model.n_faces,):
            raise InputError(f"face_active must have shape ({model.n_faces},), got {act.shape}")
        return cls(np.array(pos, order="C"), pins.copy(), act.copy(), Contacts.empty(model.n_vertices))

    def check(self, model: ClothModel) -> None:
        """Raise InputError unless this state fits `model` (sizes); makes positions contiguous float64."""
        if not isinstance(model, ClothModel):
            raise InputError("expected a ClothModel")
        nv, nf = model.n_vertices, model.n_faces
        if (
            self.positions.shape != (nv, 3)
            or self.pinned.shape != (nv,)
            or self.face_active.shape != (nf,)
            or self.contacts.face.shape != (nv,)
        ):
            raise InputError(
                f"state does not fit the model: positions {self.positions.shape}, face_active "
                f"{self.face_active.shape} for {nv} vertices and {nf} faces"
            )
        if not self.positions.flags.c_contiguous or self.positions.dtype != np.float64:
            self.positions = np.ascontiguousarray(self.positions, dtype=np.float64)

    def holding(self, pinned: np.ndarray) -> ClothState:
        """This state with other pins: `pinned` (V,) bool held where they are instead of `self.pinned`. It shares
        everything else (positions, contacts, velocities, buffers), so a stage run on it moves this state's cloth
        while this state's own pins stay as they are: how a pipeline passes each stage its pins."""
        held = np.asarray(pinned, dtype=bool)
        if held.shape != self.pinned.shape:
            raise InputError(f"pinned must have shape {self.pinned.shape}, got {held.shape}")
        return ClothState(self.positions, held, self.face_active, self.contacts, self.velocities, self._work)

    def copy(self) -> ClothState:
        c = Contacts(*(getattr(self.contacts, f.name).copy() for f in fields(Contacts)))
        v = None if self.velocities is None else self.velocities.copy()
        return ClothState(self.positions.copy(), self.pinned.copy(), self.face_active.copy(), c, v)


def locality_order(faces: np.ndarray, n_vertices: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """A vertex and face order with good memory locality (reverse Cuthill-McKee over the edges; faces by their
    lowest new vertex). The relaxation reads neighbours' data: a mesh in random order runs about a quarter slower.

    Returns (vertex_order (V,), face_order (F,)) int64: new vertex k is old vertex vertex_order[k]; apply as
    `positions[vertex_order]`, `rank[faces[face_order]]` with `rank = argsort(vertex_order)`.
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import reverse_cuthill_mckee

    f = _as_faces(faces)
    n = int(f.max()) + 1 if n_vertices is None else int(n_vertices)
    e = f[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2)
    g = coo_matrix((np.ones(len(e)), (e[:, 0], e[:, 1])), shape=(n, n)).tocsr()
    vorder = np.asarray(reverse_cuthill_mckee(g, symmetric_mode=False), dtype=np.int64)
    rank = np.empty(n, dtype=np.int64)
    rank[vorder] = np.arange(n)
    forder = np.argsort(rank[f].min(axis=1), kind="stable").astype(np.int64)
    return vorder, forder
