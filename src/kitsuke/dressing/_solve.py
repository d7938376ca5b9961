"""Wrap step 3: closing the grown garment with a global (local/global, "as-rigid-as-possible") relaxation.

Why not only `kitsuke.cloth.relax`: its Jacobi averaging moves each vertex towards the mean of its triangles'
goals, so a distortion spread over the whole garment (pieces grown from different strokes meeting at a seam
with a gap of centimetres) diffuses out one ring per iteration. Measured on the shirt at 1.5 cm: after growth
the edge strain is 15 % mean; 200 iterations of `relax` leave 11 %, and 1200 iterations without any collider
still leave 2.6 % mean and 58 % max.

Here each iteration (1) fits every triangle's rest shape to its current corners (the same kernel as `relax`:
`shape_match_goals`, with un-flipping), then (2) solves one sparse linear system for all vertices at once so
that every triangle edge best matches its goal edge (least squares; the matrix is a graph Laplacian plus a
proximal term, factorised once), then (3) runs the collision update. Pinned vertices stay where they are.
A handful of iterations removes the large-scale distortion that `relax` needs thousands for. What it does not
remove: the collision is applied after each solve, not inside it, so where the solve pulls cloth into the body
(the shirt's armpits) the two alternate by millimetres; measured on the shirt the strain plateaus at ~3 % mean
after 40 iterations (120 iterations: 3.1 %). Holding the contacts inside the solve (a heavier proximal weight,
refactorised when contacts change) did not help: weight 0.2 gave 4.6 % instead of 4.9 %, weight 1 tore it.
"""

from __future__ import annotations

import numpy as np

from ..cloth import BodyCollider, ClothModel, ClothState, collide, sweep
from ..cloth import _kernels as K

#: Weight of the proximal term (each vertex held towards where it is), relative to one triangle edge's weight:
#: small, it only keeps the system well posed and damps the fight with collision.
PROXIMAL = 0.02
#: Weight of a pinned vertex (effectively fixed; they are also reset exactly after each solve).
PINNED = 1e6
#: Most conjugate-gradient iterations per contact solve: an inexact solve is enough inside the outer iteration
#: (each starts from the last positions). Measured on the kimono: 8 leave 2.1 % mean strain where 40 leave
#: 1.8 %; the solve stops early when converged.
CG_ITERATIONS = 40


class GlobalRelax:
    """A factorised local/global relaxation of `model`.

    pinned : (V,) bool, vertices that do not move. held : (V,) bool or None, vertices pulled towards `targets`
    (V, 3) metres with `hold_weight` (relative to one triangle edge's weight; soft: the garment may yield where
    the strokes ask for more than it can give). Uses `model.params.unflip` and the collider's contact offset.
    contact_weight : body contacts as planes inside the solve (see `_solve_with_contacts`); 0: collision only
    after each solve. contact_reach_m : a vertex within this distance of the body (metres) gets a contact plane, at
    the contact offset; None: the model's contact distance, so the solve also draws cloth near the body onto it
    (the wrap's close). The drag passes the offset itself (plus round-off): drawn in, a skirt hung over the
    buttocks was pulled into the hollow below them, 27 % compression after a 5 cm lift.
    gravity_m : metres a free vertex (no edge pulling it back) moves down per step; 0 (the close): none.
    stick_weight : static friction for the gravity settle: a vertex touching the body at its first step is held
    along the body (tangentially; leaving the body stays free) at where it was, with this weight relative to
    one triangle edge, until the solve pulls it off. Without it, gravity slides the whole garment down the
    body (the contact planes are frictionless). cg_iterations : most conjugate-gradient iterations of a contact
    solve. max_move_m : most metres a vertex moves in one step (the step's move is cut back to it), None: no
    limit (the drag's small steps). sweep_below_y : a move that ends below this height (metres) deep inside a
    limb, where the collision would push it out through the limb's far side, stops where it entered the limb
    (`kitsuke.cloth.sweep`); None: no move is swept. All faces must be active (it runs after growth).
    """

    def __init__(
        self,
        model: ClothModel,
        pinned: np.ndarray,
        held: np.ndarray | None = None,
        targets: np.ndarray | None = None,
        hold_weight: float = 1.0,
        contact_weight: float = 0.0,
        contact_reach_m: float | None = None,
        gravity_m: float = 0.0,
        stick_weight: float = 0.0,
        cg_iterations: int = CG_ITERATIONS,
        max_move_m: float | None = None,
        sweep_below_y: float | None = None,
    ):
        from scipy.sparse import coo_matrix
        from scipy.sparse.linalg import splu

        self.model = model
        f = model.faces
        nv = model.n_vertices
        self.i = f.reshape(-1)  # corner k of face t -> edge (k, k+1)
        self.j = np.roll(f, -1, axis=1).reshape(-1)
        ones = np.ones(len(self.i))
        diag = np.bincount(self.i, minlength=nv) + np.bincount(self.j, minlength=nv)
        self.anchor = np.where(pinned, PINNED, PROXIMAL).astype(np.float64)
        self.held = np.zeros(nv, dtype=bool) if held is None else held & ~pinned
        self.anchor[self.held] = hold_weight
        self.targets = None if targets is None else np.asarray(targets, dtype=np.float64).copy()
        rows = np.concatenate([self.i, self.j, np.arange(nv)])
        cols = np.concatenate([self.j, self.i, np.arange(nv)])
        vals = np.concatenate([-ones, -ones, diag + self.anchor])
        a = coo_matrix((vals, (rows, cols)), shape=(nv, nv)).tocsc()
        self.lu = splu(a)
        self.precond = self.lu  # of the contact solve's conjugate gradients
        self.a = a.tocsr()
        self.contact_weight = float(contact_weight)
        self.contact_reach_m = contact_reach_m
        self.gravity_m = float(gravity_m)
        self.stick_weight = float(stick_weight)
        self.stuck: np.ndarray | None = None  # vertices held by static friction, set at the first step
        self.stick_at: np.ndarray | None = None  # (V, 3) where they were then
        self.released = np.zeros(nv, dtype=bool)
        self.cg_iterations = 0
        self.cg_limit = int(cg_iterations)
        self.pinned = pinned.copy()
        self.max_move_m = max_move_m
        self.sweep_below_y = sweep_below_y
        nf = model.n_faces
        self._normals = np.zeros((nf, 3))
        self._ref = np.zeros((nf, 3))
        self._flipped = np.zeros(nf, dtype=np.uint8)
        self._goals = np.zeros((nf, 3, 3))

    def step(self, state: ClothState, collider: BodyCollider | None) -> float:
        """One local/global iteration (in place on `state`); returns the largest vertex move, metres (before the
        `max_move_m` cut).

        collider : the body, for the contact planes inside the solve (when `contact_weight` > 0) and the collision
        after it; None: neither."""
        m = self.model
        pos = state.positions
        K.reference_normals(
            pos,
            m.faces,
            m.face_adjacency,
            m.face_adjacency_sign,
            state.face_active,
            m.params.unflip,
            self._normals,
            self._ref,
            self._flipped,
        )
        K.shape_match_goals(pos, m.faces, m.rest_corners, self._ref, state.face_active, self._goals)
        g = self._goals
        d = (g - np.roll(g, -1, axis=1)).reshape(-1, 3)  # goal edge vectors, ordered like self.i / self.j
        nv = m.n_vertices
        rhs = self.anchor[:, None] * pos
        if self.targets is not None:
            rhs[self.held] = self.anchor[self.held, None] * self.targets[self.held]
        for c in range(3):
            rhs[:, c] += np.bincount(self.i, weights=d[:, c], minlength=nv)
            rhs[:, c] -= np.bincount(self.j, weights=d[:, c], minlength=nv)
        if self.gravity_m:  # the proximal weight times the move: a free vertex moves down by gravity_m
            rhs[~self.pinned, 1] -= PROXIMAL * self.gravity_m
        if self.contact_weight > 0 and collider is not None:
            p = m.params
            reach = p.contact_distance_m if self.contact_reach_m is None else self.contact_reach_m
            new = self._solve_with_contacts(state, rhs, collider, p.contact_offset_m, reach)
        else:
            new = self.lu.solve(rhs)
        new[self.pinned] = pos[self.pinned]
        length = np.sqrt(((new - pos) ** 2).sum(axis=1))
        move = float(length.max(initial=0.0))
        if self.max_move_m is not None and move > self.max_move_m:
            over = length > self.max_move_m
            new[over] = pos[over] + (new[over] - pos[over]) * (self.max_move_m / length[over])[:, None]
        if collider is not None and self.sweep_below_y is not None:
            sweep(pos, new, ~self.pinned, collider, below_y=self.sweep_below_y)
        pos[:] = new
        if collider is not None:
            collide(m, state, collider)
        return move

    def _precondition_sticks(self) -> None:
        """Factorise A + stick_weight on the stuck vertices for the contact solve's preconditioner: the friction
        springs are as stiff as the contacts, and without them in the preconditioner the settle's conjugate
        gradients need several times the iterations. Once per settle: the stuck set only shrinks."""
        from scipy.sparse import diags
        from scipy.sparse.linalg import splu

        self.precond = splu((self.a + diags(self.stick_weight * self.stuck)).tocsc())

    def _solve_with_contacts(
        self, state: ClothState, rhs: np.ndarray, collider: BodyCollider, offset: float, reach: float
    ) -> np.ndarray:
        """Solve (A + sum_c w n_c n_c^T) x = rhs + sum_c w n_c (n_c . q_c): the body contacts as planes inside the
        global step (normal direction only, so cloth still slides along the body), with conjugate gradients
        preconditioned by the factorised A. A contact whose vertex the solve pulls off the body (outwards past
        its plane) is released for the next iteration: the plane only pushes, never glues.
        """
        c = state.contacts
        touching = (c.face >= 0) & (c.distance < reach) & ~self.pinned
        self.released &= touching
        ws = self.stick_weight
        if ws > 0:
            if self.stuck is None:
                self.stuck = touching.copy()
                self.stick_at = state.positions.copy()
                self._precondition_sticks()
            self.stuck &= touching  # held until it leaves the body (not when it only rises off its plane)
        idx = np.flatnonzero(touching & ~self.released)
        n = c.normal[idx]
        q = c.point[idx] + offset * n
        # Tangential springs to where each stuck vertex was: ws (I - n n^T) (x - s).
        si = np.zeros(0, dtype=np.int64) if self.stuck is None else np.flatnonzero(self.stuck)
        sn = c.normal[si]
        if collider.floor_y is not None:  # the floor: one more plane for the vertices near it
            low = np.flatnonzero((state.positions[:, 1] < collider.floor_y + reach) & ~self.pinned)
            idx = np.concatenate([idx, low])
            n = np.concatenate([n, np.tile([0.0, 1.0, 0.0], (len(low), 1))])
            q = np.concatenate([q, np.tile([0.0, collider.floor_y + offset, 0.0], (len(low), 1))])
        if not len(idx) and not len(si):
            return self.lu.solve(rhs)
        w = self.contact_weight
        b = rhs.copy()
        np.add.at(b, idx, w * n * (n * q).sum(axis=1, keepdims=True))
        if len(si):
            s_at = self.stick_at[si]
            b[si] += ws * (s_at - sn * (sn * s_at).sum(axis=1, keepdims=True))

        def apply(x: np.ndarray) -> np.ndarray:
            y = self.a @ x
            np.add.at(y, idx, w * n * (n * x[idx]).sum(axis=1, keepdims=True))
            if len(si):
                xs = x[si]
                y[si] += ws * (xs - sn * (sn * xs).sum(axis=1, keepdims=True))
            return y

        x = state.positions.copy()
        r = b - apply(x)
        z = self.precond.solve(r)
        p = z.copy()
        rz = float((r * z).sum())
        tol = 1e-10 * float((b * b).sum())
        it = 0
        for it in range(self.cg_limit):  # noqa: B007 (counted below)
            ap = apply(p)
            alpha = rz / float((p * ap).sum())
            x += alpha * p
            r -= alpha * ap
            if float((r * r).sum()) < tol:
                break
            z = self.precond.solve(r)
            rz_new = float((r * z).sum())
            p = z + (rz_new / rz) * p
            rz = rz_new
        self.cg_iterations += it + 1
        # Vertices held outside their plane by the penalty (they would leave the body): let them go next time.
        leaving = ((x[idx] - q) * n).sum(axis=1) > 0
        self.released[idx[leaving]] = True
        return x


def gravity_settle(
    model: ClothModel,
    state: ClothState,
    collider: BodyCollider,
    pinned: np.ndarray,
    *,
    iterations: int,
    gravity_m: float,
    stick_weight: float,
    contact_weight: float,
) -> None:
    """The wrap's `settle="global"` (in place on `state`): `iterations` global steps with gravity (`gravity_m`
    per step for a free vertex), the body contacts inside the solve and static friction holding the cloth that
    touches the body at the start (`stick_weight`); `pinned` vertices stay.

    Why besides `kitsuke.cloth.relax` with gravity (the default settle): its Jacobi averaging lets gravity
    stretch the cloth hanging below what holds it, in proportion to the length that hangs (the kimono under its
    obi band: a row of edges 8-30 % long), which the wrap's finish only partly takes back. Here the solve is
    stiff everywhere at once, so cloth that hangs swings down without stretching. Measured on the four shipped
    cases (mean edge strain, Jacobi -> global, see `SettleSettings.method`): shirt 1.43 -> 1.36 %, hoody 1.51 ->
    1.40 %, T-shirt 1.08 -> 1.02 %, kimono 1.79 -> 1.19 %; since the wrap ends with edge-length restoration
    (`kitsuke.cloth.restore_lengths`), which takes that stretch out too, both settles end at the same strain.
    """
    solver = GlobalRelax(model, pinned, contact_weight=contact_weight, gravity_m=gravity_m, stick_weight=stick_weight)
    for _ in range(iterations):
        solver.step(state, collider)
    # Global steps move cloth far enough for the tracking's walk to lose a vertex pushed into the torso under
    # the arm while it stays tracked to the arm (see `Contacts.forget`): one update with every point searched.
    state.contacts.forget()
    collide(model, state, collider)
