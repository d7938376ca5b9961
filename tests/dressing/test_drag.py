"""Dragging a dressed garment along the default body (issue 4): lift, turn, pins, rolling up a sleeve; quality after
every step; bad input.

Two garments: a skirt (a tube sewn from a flat rectangle, hung round the hips with a little ease: exactly at rest,
so every strain it shows comes from the drag) and the kimono exactly as `kitsuke demo` dresses it
(`dress_default_kimono`, 1.5 cm triangles), which meets every quality target of issue 3 (max strain 4.8 %). After
the lift, the turn, the rolled-up sleeve and rough drags every target still holds (a release refines where the drag
bunched the cloth, so the garment may come back with more vertices: old ones keep their indices) and after the
front is lifted 6 cm with the back pinned (the let-go point gives 1 cm: see that test).
"""

from __future__ import annotations

import numpy as np
import pytest

from kitsuke.cloth import BodyCollider, grid_tube
from kitsuke.dressing.drag import DragParams, DragSession
from kitsuke.dressing.export import GarmentFile
from kitsuke.errors import InputError
from kitsuke.skeleton import INDEX

#: Strain may grow by this much (fraction) where the garment was already above the 5 % target before the drag.
STRAIN_MARGIN = 0.005


def skirt_garment(body, *, y_top=0.98, rows=19, around=96, ease_m=0.012) -> tuple[GarmentFile, np.ndarray]:
    """A skirt on `body`: a rectangle sewn into a tube (one seam), hung as an elliptical cylinder just outside the
    hips. Its rest shape is the flat rectangle and its placed shape a developable cylinder with the same lengths,
    so it starts unstrained. Returns the garment and the centre (x, z) of its ellipse."""
    v = body.mesh.vertices
    hips = v[(v[:, 1] > y_top - 0.36) & (v[:, 1] < y_top) & (np.hypot(v[:, 0], v[:, 2]) < 0.3)]
    a = np.abs(hips[:, 0]).max() + ease_m
    c = 0.5 * np.ptp(hips[:, 2]) + ease_m
    cz = 0.5 * (hips[:, 2].max() + hips[:, 2].min())
    t = np.linspace(0, 2 * np.pi, 4001)
    ring = np.stack([a * np.sin(t), c * np.cos(t)], 1)
    s = np.r_[0, np.cumsum(np.linalg.norm(np.diff(ring, axis=0), axis=1))]
    spacing = s[-1] / around
    tt = np.interp(np.arange(around) * spacing, s, t)  # equal arc lengths: the flat rectangle's columns
    faces, rest, _ = grid_tube(around, rows, spacing)
    y = y_top - spacing * np.arange(rows)
    pos = np.concatenate([np.stack([a * np.sin(tt), np.full(around, yj), cz + c * np.cos(tt)], 1) for yj in y])
    return GarmentFile(pos, faces, rest, ["skirt"], np.array([[0, len(faces)]]), "skirt"), np.array([0.0, cz])


@pytest.fixture(scope="module")
def collider(body):
    return BodyCollider.from_body(body)


@pytest.fixture(scope="module")
def skirt(body):
    return skirt_garment(body)


@pytest.fixture(scope="module")
def kimono(dressed_kimono):
    return dressed_kimono


def piece_vertices(garment, name: str) -> np.ndarray:
    k = garment.piece_names.index(name)
    a, b = garment.piece_faces[k]
    return np.unique(garment.faces[a:b])


def assert_quality_kept(before, after) -> None:
    """The wrap's quality targets after a drag step (issue 3): no vertex more than 2 mm inside the body, no inverted
    triangle, seam gap <= 3 mm, max strain <= max(5 %, before + margin). For the skirt, which meets them before."""
    assert after.penetration_count == 0
    assert after.inverted_count == 0
    assert after.seam_gap_mm <= 3.0
    assert after.strain_max <= max(0.05, before.strain_max + STRAIN_MARGIN)


def assert_kimono_targets_kept(before, after) -> None:
    """The wrap's quality targets but the max strain (issue 3): kept after a drag step that the max strain target
    cannot survive (the pinned drag below)."""
    assert before.strain_mean <= 0.01 and before.inverted_count == 0 and before.penetration_count == 0
    assert after.penetration_count == 0 and after.penetration_deepest_mm <= 2.0
    assert after.inverted_count == 0
    assert after.seam_gap_mm <= 3.0
    assert after.strain_mean <= 0.01


def front_of(positions: np.ndarray, y: float) -> int:
    """The vertex a click on the front centre at height y picks: seen from the front, of the vertices within 1.5 cm
    of (x, y) = (0, y) those on the cloth nearest the viewer (within 3 mm of the largest z: the kimono's outer
    front, not the one under it), and of those the nearest (0, y)."""
    off = np.hypot(positions[:, 0], positions[:, 1] - y)
    near = np.flatnonzero(off < 0.015)
    outer = near[positions[near, 2] > positions[near, 2].max() - 0.003]
    return int(outer[np.argmin(off[outer])])


# -- (a) lift -----------------------------------------------------------------------------------------------------
def test_lift_the_skirt_moves_every_vertex_5_cm_up_along_the_body(body, skirt, collider):
    garment, _ = skirt
    s = DragSession(body, garment, collider=collider)
    before = s.report()
    x0 = s.positions.copy()
    g = front_of(x0, 0.9)
    s.grab(vertex=g)
    stats = s.move_by([0.0, 0.05, 0.0])
    s.release()
    move = s.positions[: len(x0)] - x0
    dist = np.linalg.norm(move, axis=1)
    assert stats.updates == 5 and abs(stats.grab_moved_m - 0.05) < 0.003  # chords of the 5 cm path on the body
    assert np.abs(dist - 0.05).max() <= 0.015
    assert (move[:, 1] > 0.035).all()  # up, every vertex
    assert_quality_kept(before, s.report())


@pytest.mark.slow
def test_lift_the_kimono(body, kimono, collider):
    """The kimono rises with its front: the median vertex moves 5 cm, nine in ten within 5 +- 1.5 cm, and every
    quality target still holds (measured 2026-11-25: max strain 4.77 -> 3.02 %, mean 0.33 -> 0.20 %)."""
    s = DragSession(body, kimono, collider=collider)
    before = s.report()
    x0 = s.positions.copy()
    s.grab(vertex=front_of(x0, 1.1))
    s.move_by([0.0, 0.05, 0.0])
    assert s.release().grab_gave_m == 0.0  # within the target held: the let-go point stays where it was left
    dist = np.linalg.norm(s.positions[: len(x0)] - x0, axis=1)
    assert abs(np.median(dist) - 0.05) < 0.01
    assert np.mean(np.abs(dist - 0.05) <= 0.015) >= 0.9
    assert np.median(s.positions[: len(x0), 1] - x0[:, 1]) > 0.04
    assert_quality_kept(before, s.report())


# -- (b) turn -----------------------------------------------------------------------------------------------------
def test_turn_the_skirt_30_degrees_around_the_waist(body, skirt, collider):
    """Dragging the front of the skirt 30° around the body (in 2° steps, as a mouse would) turns every vertex
    the same way about the body's axis: by 15-45° (less at the wide hips, where the same length along the body is
    a smaller angle; more at the narrow front and back), 20-32° in the median, and the skirt is not stretched:
    max strain <= 5 %."""
    garment, (cx, cz) = skirt
    s = DragSession(body, garment, collider=collider)
    before = s.report()
    x0 = s.positions.copy()
    g = front_of(x0, 0.9)
    s.grab(vertex=g)
    r = x0[g] - [cx, x0[g, 1], cz]
    for deg in range(2, 31, 2):
        a = np.radians(deg)
        s.move_to([cx + np.cos(a) * r[0] + np.sin(a) * r[2], x0[g, 1], cz - np.sin(a) * r[0] + np.cos(a) * r[2]])
    s.release()
    angle0 = np.arctan2(x0[:, 0] - cx, x0[:, 2] - cz)
    angle1 = np.arctan2(s.positions[: len(x0), 0] - cx, s.positions[: len(x0), 2] - cz)
    turn = np.degrees((angle1 - angle0 + np.pi) % (2 * np.pi) - np.pi)
    assert 15 <= turn.min() and turn.max() <= 45
    assert 20 <= np.median(turn) <= 32
    assert abs(turn[g] - 30) < 1.0
    assert np.abs(s.positions[: len(x0), 1] - x0[:, 1]).max() < 0.015  # a turn, not a lift
    after = s.report()
    assert after.strain_max <= 0.05
    assert_quality_kept(before, after)


@pytest.mark.slow
def test_turning_the_kimono_leaves_its_sleeves_round_the_arms(body, kimono, collider):
    """The kimono's front dragged 2 cm sideways, no pins: a turn about the torso. Its body turns; the cloth round
    the forearms does not (turned about the torso it was swept through the arms: 339 % max strain after one 1 cm
    update), the turn fading out over the cloth between; after the release every quality target holds (measured
    2026-11-25: 4.50 % max strain)."""
    s = DragSession(body, kimono, collider=collider)
    before = s.report()
    x0 = s.positions.copy()
    grab = s.grab(vertex=front_of(x0, 1.1))
    j = body.rig.joints
    elbow, wrist = j[INDEX["l_elbow"]], j[INDEX["l_wrist"]]
    t = np.clip((x0 - elbow) @ (wrist - elbow) / np.sum((wrist - elbow) ** 2), 0, 1)
    forearm = np.linalg.norm(x0 - (elbow + t[:, None] * (wrist - elbow)), axis=1) < 0.06  # cloth round the forearm
    front = (np.abs(x0[:, 0]) < 0.05) & (x0[:, 2] > 0.1) & (np.abs(x0[:, 1] - 1.1) < 0.05)
    assert forearm.sum() > 50 and (grab.turn[forearm] == 0).all() and (grab.turn[front] == 1).all()
    # The turn fades smoothly along the cloth: no edge changes it by more than its length over the blend.
    e, length = s.model.edges, s.model.rest_lengths
    assert (np.abs(np.diff(grab.turn[e], axis=1)[:, 0]) <= 1.5 * length / DragParams().turn_blend_m + 1e-9).all()
    s.move_by([0.02, 0.0, 0.0])
    move = s.positions[: len(x0)] - x0
    assert np.median(np.linalg.norm(move[front], axis=1)) > 0.015
    assert np.median(np.linalg.norm(move[forearm], axis=1)) < 0.005
    s.release()
    assert_quality_kept(before, s.report())


def test_a_body_without_capsules_turns_everything(body, skirt):
    """A bare mesh body (no rig, no capsules): the vertical axis, and every vertex takes the whole turn."""
    garment, _ = skirt
    s = DragSession(body.mesh, garment)
    x0 = s.positions.copy()
    grab = s.grab(vertex=front_of(x0, 0.9))
    assert (grab.turn == 1).all() and np.allclose(grab.axis, [0, 1, 0])
    s.move_by([0.02, 0.0, 0.0])
    assert np.median(np.linalg.norm(s.positions - x0, axis=1)) > 0.01  # the whole skirt turned


# -- (c) pins -----------------------------------------------------------------------------------------------------
@pytest.mark.slow
def test_pins_down_the_back_stop_a_drag_of_the_front(body, kimono, collider):
    """A row of pins down the kimono's back seam (and the back of its collar): dragging the front up 6 cm leaves
    the pinned vertices exactly where they were, does not reach the half beyond the pins at all (< 5 mm: not a
    micrometre), moves the near half, and every quality target still holds. Held 6 cm up, the cloth between the
    let-go point and the pins would stay stretched (8.1 %); let go, it pulls that point back 1 cm and meets the
    5 % (measured 2026-11-25: 4.77 -> 4.84 % max strain; `DragParams.release_give_m`)."""
    s = DragSession(body, kimono, collider=collider)
    before = s.report()
    x0 = s.positions.copy()
    seam = np.intersect1d(piece_vertices(kimono, "migoro_left"), piece_vertices(kimono, "migoro_right"))
    eri = piece_vertices(kimono, "eri")
    pins = np.union1d(seam, eri[(np.abs(x0[eri, 0]) < 0.02) & (x0[eri, 2] < 0.05)])
    s.pin(x0[pins])  # as points, as a drags file gives them
    assert (np.flatnonzero(s.pinned) == pins).all()
    grab = s.grab(vertex=front_of(x0, 1.1))
    assert "okumi_left" in [n for n in kimono.piece_names if grab.vertex in piece_vertices(kimono, n)]  # the outer
    for _ in range(3):
        s.move_by([0.0, 0.02, 0.0])
    held_at = s.positions[grab.vertex].copy()
    released = s.release()
    move = np.linalg.norm(s.positions[: len(x0)] - x0, axis=1)
    beyond = grab.held & ~s.pinned[: len(x0)]
    assert (s.positions[pins] == x0[pins]).all()
    assert beyond.sum() > 0.3 * s.n_vertices and move[beyond].max() < 0.005
    # It gave at most the largest give, and says how far.
    gave = np.linalg.norm(s.positions[grab.vertex] - held_at)
    assert np.isclose(released.grab_gave_m, gave) and gave <= DragParams().release_give_m[-1] + 1e-6
    assert move[grab.vertex] > 0.06 - gave - 0.005
    reached = ~grab.held
    assert np.median(move[reached]) > 0.01
    # Attenuated towards the pins: cloth next to a pin barely moves.
    assert move[reached & (grab.distance_pin_m < 0.03)].max() < 0.5 * move[grab.vertex]
    after = s.report()
    assert after.strain_max <= 0.05 and released.strain_max == pytest.approx(after.strain_max, abs=1e-6)
    assert_kimono_targets_kept(before, after)


def test_a_pin_attenuates_the_drag_without_a_kink(body, skirt, collider):
    """One pin at the back of the skirt: lifting the front 3 cm leaves the pin exactly where it was, and along the
    skirt's round through the pin the moves fall smoothly towards it from either side (no neighbour of the pin
    moves a quarter of the grab's move; each step nearer the pin moves less)."""
    garment, _ = skirt
    s = DragSession(body, garment, collider=collider)
    x0 = s.positions.copy()
    back = int(np.argmin(x0[:, 2] + 5 * np.abs(x0[:, 1] - 0.9) + 5 * np.abs(x0[:, 0])))
    s.pin(vertices=[back])
    grab = s.grab(vertex=front_of(x0, 0.9))
    s.move_by([0.0, 0.03, 0.0])
    s.release()
    move = np.linalg.norm(s.positions[: len(x0)] - x0, axis=1)
    assert move[back] == 0.0 and move[grab.vertex] > 0.025
    around = 96  # the skirt's vertices per round: vertex j * around + i
    row, col = divmod(back, around)
    for side in (1, -1):
        ring = [row * around + (col + side * k) % around for k in range(5)]
        assert move[ring[1]] < 0.25 * move[grab.vertex]
        assert (np.diff(move[ring]) > 0).all()


# -- (d) roll up a sleeve -----------------------------------------------------------------------------------------
def roll_up_left_sleeve(s: DragSession, body, kimono):
    """Pin a band round the kimono's left upper arm (7-10.5 cm from the shoulder seam, across the sleeve), drag the
    top of the hand opening 10 cm up the forearm towards the elbow, let go. Returns the sleeve's pattern positions
    (V, 2) cm (NaN off the sleeve), its vertices, the band and the cuff vertex."""
    k = kimono.piece_names.index("sode_left")
    fa, fb = kimono.piece_faces[k]
    uv = np.full((s.n_vertices, 2), np.nan)
    uv[kimono.faces[fa:fb].reshape(-1)] = kimono.corner_uv[fa:fb].reshape(-1, 2) * 100  # pattern cm
    sleeve = np.flatnonzero(np.isfinite(uv[:, 0]))
    band = sleeve[(uv[sleeve, 0] > 7) & (uv[sleeve, 0] < 10.5)]
    s.pin(vertices=band)
    cuff = int(sleeve[np.argmin(np.hypot(uv[sleeve, 0] - 32, uv[sleeve, 1] - 49))])  # top of the hand opening
    j = body.rig.joints
    elbow, wrist = j[INDEX["l_elbow"]], j[INDEX["l_wrist"]]
    s.grab(vertex=cuff)
    s.move_to(elbow + 0.35 * (wrist - elbow))
    s.release()
    return uv, sleeve, band, cuff


@pytest.mark.slow
def test_roll_up_a_kimono_sleeve(body, kimono, collider):
    """Pins round the upper arm of the left sleeve (a band across it, 7-10.5 cm from the shoulder seam), the cuff
    dragged 10 cm up the forearm towards the elbow: the cuff goes, the shoulder stays, and every quality target
    still holds: the release refines the sleeve where it bunched so that it buckles (measured 2026-11-25: max
    strain 4.77 %; 35 % when the release kept the 1.5 cm triangles)."""
    s = DragSession(body, kimono, collider=collider)
    before = s.report()
    x0 = s.positions.copy()
    uv, sleeve, band, cuff = roll_up_left_sleeve(s, body, kimono)
    j = body.rig.joints
    shoulder, elbow, wrist = j[INDEX["l_shoulder"]], j[INDEX["l_elbow"]], j[INDEX["l_wrist"]]
    move = s.positions[: len(x0)] - x0
    forearm = (wrist - elbow) / np.linalg.norm(wrist - elbow)
    assert move[cuff] @ forearm < -0.08  # the cuff went up the forearm by 8 cm or more
    assert (move[band] == 0).all()
    near_shoulder = np.linalg.norm(x0 - shoulder, axis=1) < 0.1
    assert near_shoulder.sum() > 20 and np.abs(move[near_shoulder]).max() == 0.0
    assert np.median(move[sleeve[uv[sleeve, 0] > 25]] @ forearm) < -0.005  # the cuff's end of the sleeve bunches up
    assert_quality_kept(before, s.report())
    # The release refined the bunched sleeve: more vertices (the old keep their indices and their pins), each piece's
    # faces still contiguous, and the garment written and read back as it is.
    assert s.n_vertices > len(x0) and s.pinned[band].all() and not s.pinned[len(x0) :].any()
    out = s.garment()
    assert len(out.faces) == s.model.n_faces and out.piece_faces[-1, 1] == len(out.faces)
    assert (out.piece_faces[1:, 0] == out.piece_faces[:-1, 1]).all()
    np.testing.assert_array_equal(out.corner_uv, s.model.rest_corners)  # the pattern shape of every new face
    assert np.isfinite(out.corner_uv).all() and out.piece_names == kimono.piece_names


@pytest.mark.slow
def test_restore_undoes_a_refining_release(body, kimono, collider):
    """A drags file found bad after a release that refined the garment puts it back as it was: the same vertices
    (count and positions), faces and pins."""
    s = DragSession(body, kimono, collider=collider)
    x0 = s.positions.copy()
    snap = s.snapshot()
    roll_up_left_sleeve(s, body, kimono)
    assert s.n_vertices > len(x0)  # refined
    s.restore(snap)
    assert s.n_vertices == len(x0) and np.array_equal(s.positions, x0)
    assert np.array_equal(s.model.faces, kimono.faces) and not s.pinned.any()
    assert s.report().strain_max == pytest.approx(kimono.report.strain_max, abs=1e-6)


# -- rough drags ---------------------------------------------------------------------------------------------------
@pytest.mark.slow
def test_rough_drags_up_and_down_do_not_tear_the_coarse_kimono(body, collider):
    """The kimono at 2.5 cm (as benchmarks/bench_drag.py drags it) lifted 10 cm by its front and put back, three
    times, in 1 cm updates: its hem round the shins does not tear (206 % max strain, 2.8 % mean, when collision
    only followed the global relaxation and fought it), and every quality target still holds. Measured
    2026-11-25: dressed 0.30 % / 4.53 %, after 0.23 % / 4.50 % mean / max strain (before the okumi's slanted top
    and the shoulder strokes off the neck point: dressed 0.55 % / 37 %, after 0.49 % / 13 %)."""
    from kitsuke.dressing import WrapParams
    from kitsuke.dressing.kimono import dress_default_kimono

    coarse = dress_default_kimono(body, params=WrapParams(edge_length_cm=2.5))
    s = DragSession(body, coarse, collider=collider)
    before = s.report()
    s.grab(vertex=front_of(s.positions, 1.1))
    for _ in range(3):
        s.move_by([0.0, 0.1, 0.0])
        s.move_by([0.0, -0.1, 0.0])
    s.release()
    after = s.report()
    assert_quality_kept(before, after)
    assert after.strain_max < before.strain_max + 0.1  # torn: 206 %


# -- API behaviour and bad input ----------------------------------------------------------------------------------
def test_session_takes_the_garment_file_and_reports_timings(body, skirt, collider):
    garment, _ = skirt
    s = DragSession(body, garment, collider=collider, params=DragParams(max_step_m=0.004))
    g = s.grab(vertex=0)
    assert g.weight.shape == (s.n_vertices,) and (g.weight == 1).all() and not g.held.any()
    stats = s.move_by([0.0, 0.01, 0.0])
    assert stats.updates == 3 and len(stats.update_seconds) == 3 and stats.seconds > 0
    s.release()
    out = s.garment()
    assert out.name == "skirt" and out.positions is not s.positions and np.allclose(out.positions, s.positions)


def test_bad_input_raises_and_leaves_the_garment_unchanged(body, skirt, collider):
    garment, _ = skirt
    s = DragSession(body, garment, collider=collider, source="dressed.obj")
    x0 = s.positions.copy()
    with pytest.raises(InputError, match="off the garment") as e:
        s.grab([0.0, 2.5, 0.0])
    assert "dressed.obj" in str(e.value)
    with pytest.raises(InputError, match="NaN"):
        s.grab([np.nan, 0.9, 0.1])
    with pytest.raises(InputError, match="nothing is grabbed"):
        s.move_to([0.0, 0.9, 0.2])
    s.grab(vertex=0)
    with pytest.raises(InputError, match="off the body"):
        s.move_to([0.0, 0.9, 1.5])
    with pytest.raises(InputError, match="NaN"):
        s.move_to([0.0, np.inf, 0.2])
    with pytest.raises(InputError, match="release it first"):
        s.pin(vertices=[5])
    s.release()
    assert (s.positions == x0).all()
    s.pin(vertices=[3])
    with pytest.raises(InputError, match="pinned"):
        s.grab(vertex=3)
    s.pin(vertices=np.arange(s.n_vertices))
    with pytest.raises(InputError, match="every garment vertex is pinned"):
        s.grab(vertex=4)
    s.unpin(all=True)
    assert not s.pinned.any() and (s.positions == x0).all()
    with pytest.raises(InputError):
        DragParams(near_m=0.05, far_m=0.01)
    with pytest.raises(InputError, match="release_untangle_rounds"):
        DragParams(release_untangle_rounds=-1)
    with pytest.raises(InputError, match="release_untangle_iterations"):
        DragParams(release_untangle_iterations=0)
    with pytest.raises(InputError, match="contact_iterations"):
        DragParams(contact_iterations=0)
    with pytest.raises(InputError, match="contact_weight"):
        DragParams(contact_weight=float("nan"))
    with pytest.raises(InputError, match="release_polish_rounds"):
        DragParams(release_polish_rounds=-1)
    with pytest.raises(InputError, match="release_polish_iterations"):
        DragParams(release_polish_iterations=0)
    with pytest.raises(InputError, match="release_polish_above"):
        DragParams(release_polish_above=float("nan"))
    with pytest.raises(InputError, match="release_polish_levels"):
        DragParams(release_polish_levels=-1)
    with pytest.raises(InputError, match="release_polish_max_folds"):
        DragParams(release_polish_max_folds=1.5)
    for blend in (0.0, -0.1, float("inf")):
        with pytest.raises(InputError, match="turn_blend_m"):
            DragParams(turn_blend_m=blend)
    for give in ((0.02, 0.01), (0.0,), (float("nan"),), [0.01]):
        with pytest.raises(InputError, match="release_give_m"):
            DragParams(release_give_m=give)
    with pytest.raises(InputError):
        DragSession(body, "not a garment")
