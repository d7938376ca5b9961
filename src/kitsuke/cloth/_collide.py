"""Body collision: Skin-style nearest-surface tracking, push-out, and capsule "bones" for vertices and edges."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError
from ..geometry import TriMesh
from ..geometry.surface import Surface
from . import _collide_kernels as K
from ._model import ClothModel, ClothState


def _face_adjacency(faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Face across each local edge k (corners k, k+1) of a closed, consistently wound mesh (F, 3) -1 if none, and
    how many edges lack a partner or are shared wrongly (boundary or non-manifold)."""
    nf = len(faces)
    a = faces.reshape(-1)
    b = faces[:, [1, 2, 0]].reshape(-1)
    n = int(faces.max()) + 1
    key_fwd, key_rev = a * n + b, b * n + a
    order = np.argsort(key_fwd)
    sorted_keys = key_fwd[order]
    pos = np.searchsorted(sorted_keys, key_rev)
    pos = np.minimum(pos, len(sorted_keys) - 1)
    found = sorted_keys[pos] == key_rev
    adj = np.where(found, order[pos] // 3, -1)
    duplicated = int((np.diff(sorted_keys) == 0).sum())  # a directed edge twice: non-manifold or misoriented
    return adj.reshape(nf, 3).astype(np.int64), int((~found).sum()) + duplicated


@dataclass(eq=False)
class BodyCollider:
    """A closed body surface prepared for cloth collision (build with `from_body` or `from_mesh`).

    Attributes
    ----------
    vertices : (Vb, 3) float64, metres. faces : (Fb, 3) int64, wound counter-clockwise seen from outside.
    face_normals : (Fb, 3) unit. edge_normals : (Fb, 3, 3) unit pseudo-normal of each face's edge k (corners k, k+1):
        the mean of the two faces' normals. vertex_normals : (Vb, 3) unit, angle-weighted: the sign of
        (p - nearest point) . pseudo-normal tells inside from outside exactly for the true nearest point; the same
        normals interpolated with barycentrics give the push-out direction. corner_angles : (Fb, 3) each face's
        angle at each corner, radians, as built: a `moved` body weights its vertex normals with these.
    face_adjacency : (Fb, 3) int64, face across each local edge. faces_at_ptr, faces_at : CSR of the faces around
        each vertex (for the walk).
    capsule_ends : (C, 2, 3) float64, metres; capsule_radii : (C, 2) float64, metres (tapered capsules).
    floor_y : height of the ground plane, metres, or None: cloth is kept above it (a long hem rests on the floor
        instead of hanging through it). `from_body` puts it under the feet.
    moving : a pose of a moving body (made by `moved`): global searches walk from the nearest body vertex
        (`vertex_grid`) instead of building a search tree for this pose alone.
    """

    vertices: np.ndarray
    faces: np.ndarray
    capsule_ends: np.ndarray = field(default_factory=lambda: np.zeros((0, 2, 3)))
    capsule_radii: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))
    source: str | None = None
    floor_y: float | None = None
    face_normals: np.ndarray = field(init=False, repr=False)
    edge_normals: np.ndarray = field(init=False, repr=False)
    vertex_normals: np.ndarray = field(init=False, repr=False)
    corner_angles: np.ndarray = field(init=False, repr=False)
    face_adjacency: np.ndarray = field(init=False, repr=False)
    faces_at_ptr: np.ndarray = field(init=False, repr=False)
    faces_at: np.ndarray = field(init=False, repr=False)
    moving: bool = field(init=False, repr=False, default=False)
    _grid: tuple | None = field(init=False, repr=False, default=None)

    @classmethod
    def from_mesh(
        cls,
        mesh: TriMesh,
        *,
        capsule_ends: np.ndarray | None = None,
        capsule_radii: np.ndarray | None = None,
        source: str | None = None,
        floor_y: float | None = None,
    ) -> BodyCollider:
        """Collider for a closed mesh; capsules optional ((C, 2, 3) ends and (C, 2) radii, metres).

        Raises InputError (naming `source`) for a mesh with holes, non-manifold or inconsistently wound edges:
        inside and outside are undefined there.
        """
        ends = np.zeros((0, 2, 3)) if capsule_ends is None else np.asarray(capsule_ends, dtype=np.float64)
        radii = np.zeros((0, 2)) if capsule_radii is None else np.asarray(capsule_radii, dtype=np.float64)
        if ends.ndim != 3 or ends.shape[1:] != (2, 3) or radii.shape != (len(ends), 2):
            raise InputError(f"capsules must be ends (C, 2, 3) and radii (C, 2), got {ends.shape} and {radii.shape}")
        if not (np.isfinite(ends).all() and np.isfinite(radii).all()) or (radii < 0).any():
            raise InputError("capsule ends and radii must be finite, radii >= 0")
        if len(ends) > 63:
            raise InputError(f"at most 63 capsules are supported, got {len(ends)}")
        if floor_y is not None and not np.isfinite(floor_y):
            raise InputError(f"floor_y must be a finite height in metres or None, got {floor_y!r}")
        return cls(mesh.vertices, mesh.faces, ends, radii, source, None if floor_y is None else float(floor_y))

    @classmethod
    def from_body(cls, body, posed=None, *, capsules: bool = True, floor: bool = True) -> BodyCollider:
        """Collider for a `kitsuke.body.Body`, in its rest pose or in `posed` (a PosedBody), with its capsules and
        (`floor`) the ground plane under the rest pose's lowest point (the soles)."""
        mesh = body.mesh if posed is None else body.posed_mesh(posed)
        ends, radii = body.capsule_segments(posed) if capsules else (None, None)
        floor_y = float(body.mesh.vertices[:, 1].min()) if floor else None
        return cls.from_mesh(mesh, capsule_ends=ends, capsule_radii=radii, source=body.source or None, floor_y=floor_y)

    def __post_init__(self) -> None:
        v = np.ascontiguousarray(self.vertices, dtype=np.float64)
        f = np.ascontiguousarray(self.faces, dtype=np.int64)
        if v.ndim != 2 or v.shape[1] != 3 or f.ndim != 2 or f.shape[1] != 3 or len(f) == 0:
            raise InputError("body mesh must have vertices (V, 3) and faces (F, 3)", self.source)
        if not np.isfinite(v).all():
            raise InputError("body mesh has NaN or infinite coordinates", self.source)
        self.vertices, self.faces = v, f
        self.capsule_ends = np.ascontiguousarray(self.capsule_ends, dtype=np.float64).reshape(-1, 2, 3)
        self.capsule_radii = np.ascontiguousarray(self.capsule_radii, dtype=np.float64).reshape(-1, 2)
        adj, bad = _face_adjacency(f)
        if bad:
            raise InputError(
                f"body mesh is not closed: {bad} edges are open (holes), non-manifold or wound inconsistently; "
                "cloth collision needs a closed surface",
                self.source,
            )
        self.face_adjacency = adj
        self._set_normals()
        corners = f.reshape(-1)
        order = np.argsort(corners, kind="stable")
        self.faces_at = np.ascontiguousarray(order // 3, dtype=np.int64)
        self.faces_at_ptr = np.zeros(len(v) + 1, dtype=np.int64)
        np.cumsum(np.bincount(corners, minlength=len(v)), out=self.faces_at_ptr[1:])
        self._set_capsule_box()
        self._surface: Surface | None = None

    def _set_normals(self) -> None:
        v, f, adj = self.vertices, self.faces, self.face_adjacency
        tri = v[f]
        cr = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
        length = np.linalg.norm(cr, axis=1, keepdims=True)
        fn = np.divide(cr, length, out=np.zeros_like(cr), where=length > 0)
        self.face_normals = fn
        en = fn[:, None, :] + fn[adj]
        self.edge_normals = np.ascontiguousarray(en / np.maximum(np.linalg.norm(en, axis=2, keepdims=True), 1e-300))
        vn = np.zeros_like(v)
        self.corner_angles = np.empty((len(f), 3))
        for k in range(3):
            e1 = tri[:, (k + 1) % 3] - tri[:, k]
            e2 = tri[:, (k + 2) % 3] - tri[:, k]
            cosang = np.einsum("ij,ij->i", e1, e2) / np.maximum(
                np.linalg.norm(e1, axis=1) * np.linalg.norm(e2, axis=1), 1e-300
            )
            self.corner_angles[:, k] = np.arccos(np.clip(cosang, -1.0, 1.0))
            weighted = fn * self.corner_angles[:, k, None]
            for c in range(3):  # bincount sums per vertex ~10x faster than np.add.at
                vn[:, c] += np.bincount(f[:, k], weights=weighted[:, c], minlength=len(v))
        self.vertex_normals = np.ascontiguousarray(vn / np.maximum(np.linalg.norm(vn, axis=1, keepdims=True), 1e-300))

    def _set_capsule_box(self) -> None:
        lo = self.capsule_ends.min(axis=1) - self.capsule_radii.max(axis=1, initial=0.0)[:, None]
        hi = self.capsule_ends.max(axis=1) + self.capsule_radii.max(axis=1, initial=0.0)[:, None]
        self._capsule_box = (np.ascontiguousarray(lo), np.ascontiguousarray(hi))

    def moved(self, vertices: np.ndarray, capsule_ends: np.ndarray | None = None) -> BodyCollider:
        """The same surface with new vertex positions (V, 3) (a posed body), and optionally moved capsules.

        Face indices stay valid, so cloth contacts keep tracking; call `state.contacts.forget_anchors()` after a
        large move so that far cloth vertices are searched again.
        """
        ends = self.capsule_ends if capsule_ends is None else capsule_ends
        out = object.__new__(BodyCollider)  # same topology: only what depends on the positions is recomputed
        out.vertices = np.ascontiguousarray(vertices, dtype=np.float64)
        if out.vertices.shape != self.vertices.shape or not np.isfinite(out.vertices).all():
            raise InputError("moved body vertices must be finite and as many as the collider's", self.source)
        out.faces, out.face_adjacency = self.faces, self.face_adjacency
        out.faces_at_ptr, out.faces_at = self.faces_at_ptr, self.faces_at
        out.capsule_ends = np.ascontiguousarray(ends, dtype=np.float64).reshape(-1, 2, 3)
        out.capsule_radii, out.source, out.floor_y = self.capsule_radii, self.source, self.floor_y
        # compiled: every frame of a simulation (16-30 ms in numpy on a 13,000-vertex body; the numpy `_set_normals`
        # stays for a body loaded once, whose normals the wrap's rounding-sensitive results rest on bit for bit).
        # The vertex normals keep the built body's corner angles as weights: a pose hardly changes them, and
        # measuring them again (an arccos a corner) was 70 % of the 2.8 ms a frame this takes.
        nf = len(out.faces)
        out.face_normals, out.edge_normals = np.empty((nf, 3)), np.empty((nf, 3, 3))
        out.vertex_normals = np.empty_like(out.vertices)
        out.corner_angles = self.corner_angles
        K.surface_normals(
            out.vertices,
            out.faces,
            out.face_adjacency,
            out.corner_angles,
            out.face_normals,
            out.edge_normals,
            out.vertex_normals,
        )
        out._set_capsule_box()
        out._surface = None
        out._grid = None
        out.moving = True
        return out

    def vertex_grid(self) -> tuple:
        """The body's vertices binned in cubes of about one vertex each (`K.vertex_grid`: origin, dims, cell
        size, start, items), built once per pose: a nearest-vertex query visits a few cells, not 13,000 vertices."""
        if self._grid is None:
            # column by column: numpy's reduction of a (V, 3) array along its long axis took 20 times longer
            # (0.35 ms each way on the 13,380-vertex body, once a frame of a simulation)
            v = self.vertices
            extent = np.maximum([float(np.ptp(v[:, c])) for c in range(3)], 1e-3)
            cell = max(float(np.prod(extent) / max(len(self.vertices), 1)) ** (1.0 / 3.0), 1e-3)
            origin, dims, start, items = K.vertex_grid(self.vertices, cell)
            self._grid = (origin, dims, cell, start, items)
        return self._grid

    @property
    def surface(self) -> Surface:
        """Closest-point and ray queries on the collider's surface, built once (its libigl AABB takes ~50 ms on
        a 24k-vertex body), so that a wrap placing strokes on the body and the collision share one tree."""
        if self._surface is None:
            self._surface = Surface(TriMesh(self.vertices, self.faces))
        return self._surface

    def surface_for(self, mesh: TriMesh) -> Surface:
        """`surface` where `mesh` is the collider's own surface (the same vertices and faces), else a new Surface
        on `mesh` (a collider for another pose)."""
        same = (
            mesh.vertices.shape == self.vertices.shape
            and mesh.faces.shape == self.faces.shape
            and np.array_equal(mesh.vertices, self.vertices)
            and np.array_equal(mesh.faces, self.faces)
        )
        return self.surface if same else Surface(mesh)

    def nearest(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Global nearest-surface query (`surface`): face (n,) int64, point (n, 3), distance (n,)."""
        return self.surface.nearest(points)


@dataclass
class CollisionStats:
    """What one collision update did.

    searches : vertices that needed a global (AABB) nearest-point search.
    pushed : vertices pushed out of the body (closer than the offset or inside).
    deepest_m : the deepest vertex inside the body before the push, metres (0 if none).
    """

    searches: int = 0
    pushed: int = 0
    deepest_m: float = 0.0


def _buffers(state: ClothState) -> dict:
    w = state._work
    n = len(state.positions)
    if w.get("n_collide") != n:
        w["n_collide"] = n
        w["search"] = np.zeros(n, dtype=np.uint8)
        w["movable"] = np.zeros(n, dtype=bool)
        w["near"] = np.zeros(n, dtype=np.int64)
    return w


def _while_active(model: ClothModel, state: ClothState, name: str, compute):
    """`compute()`, cached on the state under `name` while face_active (and the model's size) is unchanged."""
    w = state._work
    key = (state.face_active.tobytes(), model.n_vertices)
    if w.get(name + "_key") != key:
        w[name], w[name + "_key"] = compute(), key
    return w[name]


def active_edge_index(model: ClothModel, state: ClothState) -> np.ndarray:
    """(E',) int64 indices into model.edges of the edges of the active triangles (cached on the state while
    face_active is unchanged)."""

    def compute() -> np.ndarray:
        ef = model.edge_faces
        return np.flatnonzero(
            state.face_active[ef[:, 0]] | ((ef[:, 1] >= 0) & state.face_active[np.maximum(ef[:, 1], 0)])
        )

    return _while_active(model, state, "active_edge_index", compute)


def active_edges(model: ClothModel, state: ClothState) -> np.ndarray:
    """(E', 2) int64 edges of the active triangles (cached like `active_edge_index`)."""
    return _while_active(model, state, "active_edges", lambda: model.edges[active_edge_index(model, state)])


def vertex_active(model: ClothModel, state: ClothState) -> np.ndarray:
    """(V,) bool: vertices of at least one active triangle (cached on the state while face_active is unchanged)."""

    def compute() -> np.ndarray:
        act = np.zeros(model.n_vertices, dtype=bool)
        act[model.faces[state.face_active].reshape(-1)] = True
        return act

    return _while_active(model, state, "vertex_active", compute)


def track(model: ClothModel, state: ClothState, collider: BodyCollider, *, active: np.ndarray | None = None) -> int:
    """Refresh the nearest body point of every active cloth vertex (in place on `state.contacts`).

    Each vertex walks from its tracked body face to neighbouring faces while the nearest point gets closer; new
    vertices, failed walks and far vertices that may have come near the body get a global search: the AABB tree,
    or, on a moving body's pose, a walk from the nearest body vertex (the tree only where that walk fails).
    Returns the number of global searches.
    """
    if not isinstance(collider, BodyCollider):
        raise InputError("collider must be a BodyCollider")
    state.check(model)
    act = vertex_active(model, state) if active is None else active
    w = _buffers(state)
    _walk(model, state, collider, act, w["search"])
    idx = np.flatnonzero(w["search"])
    searched = len(idx)
    if searched and collider.moving and collider._surface is None:
        idx = _seeded_search(model, state, collider, idx, w)
    if len(idx):
        face, _, _ = collider.nearest(state.positions[idx])
        _store_found(state, collider, idx, face)
    return searched


def _walk(model: ClothModel, state: ClothState, collider: BodyCollider, active: np.ndarray, search: np.ndarray) -> None:
    """`K.walk_track` for the `active` vertices: contacts refreshed in place, `search` set where a global search
    is needed."""
    p, c = model.params, state.contacts
    K.walk_track(
        state.positions, active, collider.vertices, collider.faces, collider.face_adjacency, collider.faces_at_ptr,
        collider.faces_at, collider.face_normals, collider.edge_normals, collider.vertex_normals,
        collider.vertex_normals, p.walk_max_steps, p.track_distance_m, p.contact_distance_m, c.face, c.bary,
        c.point, c.normal, c.distance, c.anchor, c.anchor_distance, search,
    )  # fmt: skip


def _store_found(state: ClothState, collider: BodyCollider, idx: np.ndarray, face: np.ndarray) -> None:
    """The contacts of vertices idx from their nearest body faces (a global search's answer), anchored there."""
    c = state.contacts
    K.store_found(
        state.positions, idx, face, collider.vertices, collider.faces, collider.face_normals, collider.edge_normals,
        collider.vertex_normals, collider.vertex_normals, c.face, c.bary, c.point, c.normal, c.distance, c.anchor,
        c.anchor_distance,
    )  # fmt: skip


def _seeded_search(model: ClothModel, state: ClothState, collider: BodyCollider, idx: np.ndarray, w: dict):
    """The global search on a body whose tree is not built (a moved body, every frame of a simulation: building
    it cost 17-22 ms a frame, a third of the kimono's step): each vertex starts at the best face around its nearest
    body vertex (`BodyCollider.vertex_grid`) and walks to its nearest point. Returns the vertices whose walk failed
    (they get the tree)."""
    face = np.empty(len(idx), dtype=np.int64)
    origin, dims, cell, start, items = collider.vertex_grid()
    K.seed_faces(state.positions, idx, collider.vertices, collider.faces, collider.faces_at_ptr, collider.faces_at,
                 origin, dims, cell, start, items, face)  # fmt: skip
    _store_found(state, collider, idx, face)
    only = np.zeros(len(state.positions), dtype=bool)
    only[idx] = True
    _walk(model, state, collider, only, w["search"])
    return np.flatnonzero(w["search"])


def _layer_face_vertices(model: ClothModel, state: ClothState) -> np.ndarray:
    """The vertices of the active faces that have a layer (cached on the state while face_active is unchanged)."""

    def compute() -> np.ndarray:
        on = state.face_active[model.layer_faces]
        if on.all():
            return model.layer_face_vertices
        mark = np.zeros(model.n_vertices, dtype=bool)  # recomputed at every growth ring: faster than np.unique
        mark[model.faces[model.layer_faces[on]].reshape(-1)] = True
        return np.flatnonzero(mark)

    return _while_active(model, state, "layer_face_vertices", compute)


@dataclass
class LayerPlanes:
    """Where layered cloth lies against another layer (`layer_planes`): per vertex j, vertex[j] must lie at least
    the layer gap along normal[j] (unit) from the point with barycentric coordinates bary[j] (3,) in face[j] of
    the other layer. vertex, face : (n,) int64; bary, normal : (n, 3) float64."""

    vertex: np.ndarray
    face: np.ndarray
    bary: np.ndarray
    normal: np.ndarray

    @classmethod
    def empty(cls) -> LayerPlanes:
        return cls(np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros((0, 3)), np.zeros((0, 3)))


def _layer_search(model: ClothModel, state: ClothState, movable: np.ndarray | None):
    """keep_layers' search: (query vertices, moves, faces, barycentrics, normals, number moved), or None with
    nothing to do."""
    if model.face_layer is None:
        return None
    p = model.params
    if movable is None:
        movable = vertex_active(model, state) & ~state.pinned
    query = model.layer_vertices[movable[model.layer_vertices]]
    if len(query) == 0:
        return None
    others = _layer_face_vertices(model, state)
    pos = state.positions
    if len(others) == 0:
        return None
    origin, cell, dims, ptr, items = K.point_grid(pos, others, model.layer_cell_m, 8 * len(others))
    move, face = np.empty((len(query), 3)), np.empty(len(query), dtype=np.int64)
    bary, normal = np.empty((len(query), 3)), np.empty((len(query), 3))
    moved = K.layer_moves(
        pos,
        model.faces,
        model.face_layer,
        state.face_active,
        model.vertex_layer,
        model.layers_at,
        model.vertex_corners_ptr,
        model.vertex_corners,
        state.contacts.face,
        state.contacts.normal,
        state.contacts.distance,
        query,
        origin,
        cell,
        dims,
        ptr,
        items,
        pos[items],
        p.layer_reach_m,
        p.layer_gap_m,
        p.max_step_m,
        move,
        face,
        bary,
        normal,
    )
    return query, move, face, bary, normal, int(moved)


def layer_planes(model: ClothModel, state: ClothState, movable: np.ndarray | None = None) -> LayerPlanes:
    """The layer order as constraints: every movable layered vertex that lies over or under a face of another
    layer within `params.layer_reach_m` (keep_layers' search and its rule for which side is out), with the plane
    it must stay outside (a higher layer) or inside (a lower one) of, whether it does already or not. The polish
    keeps them as penalties so that its large moves cannot pass one layer through another."""
    found = _layer_search(model, state, movable)
    if found is None:
        return LayerPlanes.empty()
    query, _, face, bary, normal, _ = found
    k = face >= 0
    return LayerPlanes(query[k], face[k], bary[k], normal[k])


def keep_layers(model: ClothModel, state: ClothState, movable: np.ndarray | None = None) -> int:
    """Restore the order of the model's cloth layers (`ClothModel.face_layer`; in place): each movable vertex of
    one layer within `params.layer_reach_m` of an active face of another moves towards its side of that face, so
    that the higher layer lies `params.layer_gap_m` outside the lower one (a Jacobi step: every vertex takes half
    its shortfall, the other layer's vertices the other half). Outside is along the face's winding, or away from
    the body where the vertex is tracked near it and the face is turned inside out (`layer_moves`). Returns the
    number of vertices moved (0 for a model without layers)."""
    found = _layer_search(model, state, movable)
    if found is None:
        return 0
    query, move, moved = found[0], found[1], found[5]
    state.positions[query] += move
    return moved


#: Moves shorter than this are not swept (`sweep`): too short to pass through a limb; metres.
SWEEP_MIN_M = 0.02
#: A move whose way inside the body goes less deep than this (at its middle) grazed the body: cloth sliding round
#: it dips under its curved surface (a 5 cm slide round a 4 cm arm dips 0.8 cm); metres.
SWEEP_PASS_DEPTH_M = 0.02
#: A move that ends less deep inside than this is left to the push-out; metres.
SWEEP_END_DEPTH_M = 0.01


def sweep(
    before: np.ndarray,
    positions: np.ndarray,
    movable: np.ndarray,
    collider: BodyCollider,
    *,
    below_y: float | None = None,
) -> int:
    """Cut back, in place on `positions` (V, 3) metres, each move from `before` that went deep into the body and
    ends inside it nearer its far side: the push-out after it would finish the move through the limb (laid
    GarmentCode trousers, their back panels 20 cm behind the legs, were pulled through a knee to its front in the
    close's first step, 24 cm moves). Such a move stops where it last entered the body. Only moves of movable (V,)
    bool vertices of at least `SWEEP_MIN_M`, whose way inside goes `SWEEP_PASS_DEPTH_M` deep and that end
    `SWEEP_END_DEPTH_M` deep; a move that passes through a limb and ends outside it is kept (a side seam laid in
    front of the arm reaches the armpit so). below_y : only moves that end below this height, metres (None: all).
    Returns the number cut."""
    step = positions - before
    length = np.sqrt((step * step).sum(axis=1))
    swept = movable & (length >= SWEEP_MIN_M)
    if below_y is not None:
        swept &= positions[:, 1] < below_y
    idx = np.flatnonzero(swept)
    if not len(idx):
        return 0
    ray, hits = collider.surface.ray_hits(before[idx], step[idx])
    within = hits.distance < length[idx[ray]]
    ray, at, face = ray[within], hits.distance[within], hits.faces[within]
    if not len(ray):
        return 0
    last = np.r_[ray[1:] != ray[:-1], True]  # hits are sorted by ray, then distance
    ray, at, face = ray[last], at[last], face[last]
    v = idx[ray]
    inside = np.einsum("ij,ij->i", collider.face_normals[face], step[v]) < 0.0  # it last went in: it ends inside
    v, at = v[inside], at[inside]
    middle = before[v] + (0.5 * (at + length[v]) / length[v])[:, None] * step[v]
    near_face, _, depth = collider.surface.nearest(np.concatenate([positions[v], middle]))
    end_face, end_depth, pass_depth = near_face[: len(v)], depth[: len(v)], depth[len(v) :]
    far = np.einsum("ij,ij->i", collider.face_normals[end_face], step[v]) > 0.0
    cut = far & (end_depth > SWEEP_END_DEPTH_M) & (pass_depth > SWEEP_PASS_DEPTH_M)
    v, at = v[cut], at[cut]
    positions[v] = before[v] + (at / length[v])[:, None] * step[v]
    return len(v)


def collide(
    model: ClothModel, state: ClothState, collider: BodyCollider, *, moved: np.ndarray | None = None
) -> CollisionStats:
    """One collision update (in place): layered cloth restores its layer order (`keep_layers`); capsules push
    vertices, then edges, out; the nearest body points are tracked; vertices closer than
    `params.contact_offset_m` (or inside) move out along the body normal. Pinned vertices and vertices without an
    active triangle never move.

    moved : (V,) bool, the vertices that moved since the last collision on this (still) body, those it pushed
    included, or None (all may have). The others keep their tracked contacts and are not tested again: each lay
    outside when it was last tracked and would walk to the same body point from there, so the result is a full
    collision's to the last bit. The layers and capsules test everything, and what they move is tracked.
    """
    if not isinstance(collider, BodyCollider):
        raise InputError("collider must be a BodyCollider")
    state.check(model)
    p = model.params
    act = vertex_active(model, state)
    w = _buffers(state)
    movable = np.logical_and(act, ~state.pinned, out=w["movable"])
    pos = state.positions
    shoved = model.face_layer is not None or len(collider.capsule_ends)
    before = pos.copy() if moved is not None and shoved else None
    # Layers first: an inner layer pushed into the body comes back out below, and the outer one follows next time.
    keep_layers(model, state, movable)
    if len(collider.capsule_ends):
        lo, hi = collider._capsule_box
        margin = float(model.rest_lengths.max()) * 1.5  # an edge's far end can be this far from a capsule it cuts
        K.capsule_vertices(pos, movable, collider.capsule_ends, collider.capsule_radii, lo, hi, margin, w["near"])
        if p.edge_capsules:
            K.capsule_edges(
                pos, active_edges(model, state), movable, collider.capsule_ends, collider.capsule_radii, w["near"]
            )
    if moved is not None:
        recent = moved if before is None else moved | (pos != before).any(axis=1)
        act = act & recent
        movable = movable & recent
    searches = track(model, state, collider, active=act)
    c = state.contacts
    pushed, deepest = K.push_out(pos, movable, p.contact_offset_m, c.face, c.normal, c.distance)
    if collider.floor_y is not None:
        low = movable & (pos[:, 1] < collider.floor_y + p.contact_offset_m)
        pos[low, 1] = collider.floor_y + p.contact_offset_m
        pushed += int(low.sum())
    return CollisionStats(searches, int(pushed), float(deepest))


def compile_layers() -> None:
    """Compile the layer-order kernels (`point_grid`, `layer_moves`), or load them from numba's cache, on two
    small overlapping sheets: the same argument types as `keep_layers` on any layered garment (4 s of a cold
    `kitsuke demo`; see `kitsuke.cloth.precompile_in_background`)."""
    from ._shapes import grid_sheet

    uv, f = grid_sheet(3, 3, 0.02)
    faces = np.concatenate([f, f + len(uv)])
    layer = np.r_[np.ones(len(f), dtype=np.int8), np.full(len(f), 2, dtype=np.int8)]
    model = ClothModel.from_corners(faces, np.concatenate([uv[f], uv[f]]), face_layer=layer)
    pos = np.concatenate([np.c_[uv, np.zeros(len(uv))], np.c_[uv + 0.005, np.full(len(uv), -0.001)]])
    keep_layers(model, ClothState.new(model, pos))
