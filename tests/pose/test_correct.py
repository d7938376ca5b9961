"""Posture correction (SPEC §5.3): invariants on synthetic and real poses, kernel vs numpy reference, measures."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from kitsuke.pose import (
    PoseSequence,
    check_invariants,
    correct_poses,
    correction_measures,
    default_constraints,
    filter_poses,
    packaged_constraints,
)
from kitsuke.pose import _kernels as K
from kitsuke.pose._correct import inside_values, regions_of
from kitsuke.pose._reference import correct_reference
from kitsuke.skeleton import INDEX, JOINTS

#: The correction's rules are tested on the geometric estimate, whose limits these cases were drawn for; the
#: default table (calibrated by simulation) is tested in `test_the_default_table_corrects_real_sequences`.
TABLE = packaged_constraints("geometric")


def standing_pose() -> np.ndarray:
    """(23, 3) a person standing, metres, Y up, facing +Z, left at +X."""
    p = {
        "pelvis": (0, 0.95, 0),
        "spine": (0, 1.1, 0),
        "chest": (0, 1.3, 0),
        "neck": (0, 1.45, 0),
        "head": (0, 1.6, 0.02),
        "l_clavicle": (0.03, 1.42, 0.03),
        "l_shoulder": (0.18, 1.42, 0),
        "l_elbow": (0.2, 1.15, 0),
        "l_wrist": (0.2, 0.9, 0.05),
        "l_hip": (0.09, 0.92, 0),
        "l_knee": (0.1, 0.5, 0.02),
        "l_ankle": (0.1, 0.08, 0),
        "l_heel": (0.1, 0.02, -0.05),
        "l_toe": (0.1, 0.02, 0.15),
    }
    out = np.zeros((len(JOINTS), 3))
    for name, xyz in p.items():
        out[INDEX[name]] = xyz
        if name.startswith("l_"):
            out[INDEX["r" + name[1:]]] = (-xyz[0], xyz[1], xyz[2])
    return out


def raise_leg(pose: np.ndarray, side: str, axis: str, deg: float) -> np.ndarray:
    """The pose with one leg rotated at the hip (axis 'z': sideways, 'x': forward)."""
    q = pose.copy()
    hip = INDEX[f"{side}_hip"]
    idx = [INDEX[f"{side}_{j}"] for j in ("knee", "ankle", "heel", "toe")]
    sign = -1.0 if (side == "r") == (axis == "z") else 1.0
    rot = Rotation.from_euler(axis, sign * deg, degrees=True)
    if axis == "x":
        rot = Rotation.from_euler("x", -deg, degrees=True)  # knee forward (+Z)
    q[idx] = q[hip] + rot.apply(q[idx] - q[hip])
    return q


def seq(frames: list[np.ndarray], valid: list[bool] | None = None) -> PoseSequence:
    pos = np.array(frames)
    v = np.ones(len(pos), bool) if valid is None else np.array(valid)
    return PoseSequence(positions=pos, valid=v, times=np.arange(len(pos)) / 30.0, fps=30.0)


def test_pose_inside_is_left_bit_identical():
    s = seq([standing_pose()] * 3)
    c = correct_poses(s, TABLE)
    assert np.array_equal(c.poses.positions, s.positions)
    assert (c.status == K.INSIDE).all() and c.poses.corrected == [(), (), ()]


def test_side_raise_is_corrected_into_k_with_smallest_angle():
    raised = raise_leg(standing_pose(), "r", "z", 40)  # right leg out to the side, knee 0.46 m from the left one
    c = correct_poses(seq([raised]), TABLE)
    q = c.poses.positions[0]
    assert c.poses.corrected[0][0] == "r_knee" and c.status[0, 0] == K.ROTATED
    # first frame: K' is the current K; the corrected knee is inside it (and within 0.1 mm of its edge)
    ell, excess = regions_of(raised[None], TABLE, "knee")
    assert excess[0] > 0.1
    assert inside_values(q[None, INDEX["r_knee"], ::2], ell)[0] <= 0
    # the knee came down and in (rotation toward the kimono's region), bones kept their lengths
    assert q[INDEX["r_knee"], 0] > raised[INDEX["r_knee"], 0] and q[INDEX["r_knee"], 1] < raised[INDEX["r_knee"], 1]
    for a, b in (("r_hip", "r_knee"), ("r_knee", "r_ankle"), ("r_ankle", "r_toe"), ("r_ankle", "r_heel")):
        la = np.linalg.norm(q[INDEX[b]] - q[INDEX[a]])
        assert abs(la - np.linalg.norm(raised[INDEX[b]] - raised[INDEX[a]])) < 1e-12
    # smallest angle: no smaller rotation about the same axis reaches inside (up to the 0.1 mm tolerance)
    s = raised[INDEX["r_knee"]] - raised[INDEX["r_hip"]]
    w = q[INDEX["r_knee"]] - raised[INDEX["r_knee"]]
    e = np.cross(s, w)
    e /= np.linalg.norm(e)
    angle = c.angle_rad[0, 0]
    alphas = np.linspace(0, angle - 1e-4 / np.linalg.norm(s), 2000)
    pts = raised[INDEX["r_hip"]] + Rotation.from_rotvec(alphas[:, None] * e).apply(s)
    assert (inside_values(pts[:, ::2], np.repeat(ell, len(alphas), 0)) > 0).all()


def test_previous_corrected_frame_gives_k_prime_and_gaps_restart():
    stand = standing_pose()
    frames = [
        stand,
        raise_leg(stand, "r", "z", 35),
        raise_leg(stand, "r", "z", 40),
        stand,
        raise_leg(stand, "r", "z", 40),
    ]
    c = correct_poses(seq(frames, [True, True, True, False, True]), TABLE)
    q = c.poses.positions
    # frame 2's K' is K of the corrected frame 1
    assert np.allclose(c.regions[2, 0], regions_of(q[1:2], TABLE, "knee")[0][0], atol=1e-12)
    # frame 4 follows a frame without a pose: its K' is its own current K
    assert np.allclose(c.regions[4, 0], regions_of(np.array(frames[4:5]), TABLE, "knee")[0][0], atol=1e-12)
    assert check_invariants(c)["ok"]


def test_gradual_side_raise_keeps_every_invariant():
    stand = standing_pose()
    degs = np.concatenate([np.linspace(0, 60, 40), np.linspace(60, 0, 40)])
    c = correct_poses(seq([raise_leg(stand, "r", "z", d) for d in degs]), TABLE)
    inv = check_invariants(c)
    assert inv["ok"], inv
    assert inv["continuity_checked"] > 20
    rot = c.rotated[:, 0]
    assert rot.sum() > 30 and not rot[:5].any()  # the small raises stay untouched
    assert correction_measures(c)["residual_mm"]["max"] == 0.0


def test_out_of_reach_is_reported_not_crashed():
    stand = standing_pose()
    far = raise_leg(stand, "r", "z", 50) + np.array([1.5, 0.0, 0.0])  # the whole body jumped 1.5 m sideways
    c = correct_poses(seq([stand, far]), TABLE)
    assert c.status[1, 0] in (K.CLOSEST, K.UNREACHABLE) and c.residual_m[1, 0] > 0
    inv = check_invariants(c)
    assert inv["unreachable"] >= 1 and inv["lengths_changed"] == 0 and inv["untouched_changed"] == 0


def test_numba_kernel_matches_numpy_reference(balancing_raw, kick):
    for poses in (balancing_raw, kick.subset(slice(120, 200))):
        c = correct_poses(poses, TABLE, max_jump_m=np.inf, side_margin_m=np.inf)
        ref, targets = correct_reference(poses.positions, poses.valid, TABLE)
        v = poses.valid
        assert np.array_equal(np.where(c.rotated, c.target, -1), targets)
        # where the smallest angle is bracketed and bisected, both give the same result to 1e-7 m (the closest
        # ellipse point, hence the axis, is computed differently); out-of-reach targets (golden section vs scipy's
        # bounded minimiser) agree to the 0.1 mm tolerance, and the difference fades over the following frames
        closest = np.flatnonzero((c.status == K.CLOSEST).any(axis=1))
        first = closest[0] if len(closest) else len(v)
        assert np.abs(c.poses.positions[:first][v[:first]] - ref[:first][v[:first]]).max() < 1e-7
        assert np.abs(c.poses.positions[v] - ref[v]).max() < 1e-3


@pytest.mark.parametrize("which", ["balancing", "balancing_filtered", "kick"])
def test_real_sequences_keep_all_invariants(which, balancing_raw, kick):
    poses = {"balancing": balancing_raw, "balancing_filtered": filter_poses(balancing_raw), "kick": kick}[which]
    c = correct_poses(poses, TABLE)
    inv = check_invariants(c)
    assert inv["untouched_changed"] == 0 and inv["targets_outside"] == 0 and inv["lengths_changed"] == 0, inv
    assert inv["max_length_change_m"] < 1e-9
    if which.startswith("balancing"):
        assert inv["ok"], inv  # continuity too
    else:
        # The kick: the target leg is kept from frame to frame (no snap of the other leg), and where the farther leg
        # is already inside K' the other one is the target; either can break the SPEC's continuity bound by a few
        # millimetres (measured 2026-11-26: 4 of 80 checks, 2.8 mm at worst; 0 on the horizontal motion).
        assert inv["continuity_broken"] <= 0.06 * inv["continuity_checked"] and inv["worst_continuity_excess_m"] < 0.01
    m = correction_measures(c)
    if which.startswith("balancing"):
        # large leg raises: frames must be corrected there, knees and ankles
        assert m["fraction_corrected"] > 0.3 and m["corrections"]["knee"] > 10 and m["corrections"]["ankle"] > 10
        assert m["residual_mm"]["max"] == 0.0
    else:
        assert m["corrections"]["knee"] > 30  # the kick
        # out of reach, or reachable only by swapping sides or jumping (measured 2026-11-26: 47 of 402)
        assert inv["unreachable"] <= 60


def test_walk_invariants(walk):
    """CMU 131 walk (994 frames @120 fps): untouched frames, targets inside K', bone lengths hold exactly. The
    SPEC's continuity bound does not hold everywhere for the SPEC's own algorithm (the rotation about the hip moves
    the knee along a circle that can cross the moving cylinder faster than either moves); on this clip 29 of 1194
    checked targets break it by at most 16 mm, 5 of them horizontally (the one-frame ankle spikes of the plain
    target rule are gone: 0 frames with both joints inside K'). Asserted as measured, so that a regression shows."""
    c = correct_poses(walk, TABLE)
    inv = check_invariants(c)
    assert inv["untouched_changed"] == 0 and inv["targets_outside"] == 0 and inv["lengths_changed"] == 0
    assert inv["continuity_broken"] <= 0.03 * inv["continuity_checked"]
    assert inv["continuity_broken_horizontal"] <= 0.01 * inv["continuity_checked"]
    assert inv["worst_continuity_excess_m"] < 0.02
    m = correction_measures(c)
    assert m["status_counts"]["ankle"].get("both joints already inside K'", 0) <= 2
    assert 0.5 < m["fraction_corrected"] < 0.95 and m["time_per_frame_ms"] >= 0


def test_file_round_trip_keeps_invariants(tmp_path, balancing_raw):
    from kitsuke.pose import read_poses, write_poses

    c = correct_poses(balancing_raw, TABLE)
    back = read_poses(write_poses(c.poses, tmp_path / "c.json"))
    untouched = np.array([not t for t in back.corrected])
    assert np.array_equal(back.positions[untouched & back.valid], balancing_raw.positions[untouched & back.valid])
    assert np.array_equal(back.positions, c.poses.positions, equal_nan=True)


def test_measures_content(balancing_raw):
    m = correction_measures(correct_poses(balancing_raw, TABLE))
    assert set(m) >= {"fraction_corrected", "residual_mm", "max_jump_m", "invariants", "time_per_frame_ms"}
    assert set(m["max_jump_m"]) == {f"{s}_{j}" for s in "lr" for j in ("knee", "ankle", "heel", "toe")}
    assert math.isclose(m["fraction_corrected"], m["corrected_frames"] / m["valid_frames"], rel_tol=1e-5)


def test_invalid_frames_pass_through():
    stand = standing_pose()
    s = seq([stand, stand, raise_leg(stand, "r", "z", 45)], [True, False, True])
    c = correct_poses(s, TABLE)
    assert np.isnan(c.poses.positions[1]).all() and (c.status[1] == K.INVALID).all()
    assert c.rotated[2, 0]


# -- plausibility: legs held by a kimono still look like legs ------------------------------------------------------
def knee_raise(frames: int = 40, top_deg: float = 100.0) -> np.ndarray:
    """(frames, 23, 3): the right thigh raised forward from 0 to `top_deg` and back down, the left leg standing."""
    stand = standing_pose()
    deg = top_deg * np.sin(np.linspace(0.0, np.pi, frames))
    return np.stack([raise_leg(stand, "r", "x", d) for d in deg])


@pytest.mark.parametrize("case", ["knee_raise", "side_kick", "front_kick"])
def test_corrected_legs_keep_their_side_and_do_not_jump(case):
    stand = standing_pose()
    if case == "knee_raise":
        frames = knee_raise()
    elif case == "side_kick":
        frames = np.stack([raise_leg(stand, "l", "z", d) for d in 70 * np.sin(np.linspace(0, np.pi, 30))])
    else:  # the straight left leg swung forward to 80 degrees and back in half a second (16 frames at 30 fps;
        # in 12 frames one transition jumps 31 cm past the allowance: no rotation of the shin can follow)
        frames = np.stack([raise_leg(stand, "l", "x", d) for d in 80 * np.sin(np.linspace(0, np.pi, 16))])
    c = correct_poses(seq(list(frames)), TABLE)
    inv = check_invariants(c)
    assert c.rotated.any(), "the case must need a correction"
    assert inv["sides_swapped"] == 0 and inv["jumps_over_limit"] == 0, inv
    assert inv["untouched_changed"] == 0 and inv["targets_outside"] == 0 and inv["lengths_changed"] == 0, inv


def test_without_the_rules_the_knee_raise_swaps_or_jumps():
    """The rules are what keeps the legs plausible: the SPEC's bare rotation breaks them on the same motion."""
    c = correct_poses(seq(list(knee_raise())), TABLE, max_jump_m=np.inf, side_margin_m=np.inf)
    inv = check_invariants(c)
    assert inv["sides_swapped"] > 0 or inv["jumps_over_limit"] > 0, inv


@pytest.mark.parametrize("which", ["balancing", "kick", "walk"])
def test_real_sequences_keep_sides_and_mostly_do_not_jump(which, balancing_raw, kick, walk):
    poses = {"balancing": balancing_raw, "kick": kick, "walk": walk}[which]
    c = correct_poses(poses, TABLE)
    inv = check_invariants(c)
    assert inv["sides_swapped"] == 0, inv
    if which == "balancing":
        # measured 0 here; MediaPipe's numbers move slightly between CPUs, so allow a stray transition
        assert inv["jumps_over_limit"] <= 2 and inv["worst_jump_excess_m"] < 0.05, inv
    else:
        # Mocap at full kicks and strides: where no rotation of the thigh or shin keeps every joint of the chain
        # within 5 cm of its last place, the one that jumps least is taken (measured 2026-11-26: kick 4 of 200
        # transitions, worst 18.8 cm beyond the allowance; walk 14 of 993, 7.8 cm).
        assert inv["jumps_over_limit"] <= 0.03 * poses.n_frames and inv["worst_jump_excess_m"] < 0.25, inv


@pytest.mark.parametrize("which", ["balancing", "kick", "side_kick"])
def test_the_default_table_corrects_real_sequences(which, balancing_raw, kick):
    """The default table (calibrated by simulation, 20-100 % wider than the geometric estimate) still corrects the
    large raises and the kick, keeps every invariant the rules guarantee, and swaps no sides. It lets the legs
    reach out of K' more often: a jump past the 5 cm allowance happens only in a frame whose target is out of
    reach, by millimetres (measured 2026-11-27: the side kick 1 jump, 2.2 mm over, with 3 frames out of reach)."""
    assert default_constraints().source == "calibrated"
    if which == "side_kick":
        stand = standing_pose()
        poses = seq([raise_leg(stand, "l", "z", d) for d in 70 * np.sin(np.linspace(0, np.pi, 30))])
    else:
        poses = {"balancing": balancing_raw, "kick": kick}[which]
    c = correct_poses(poses)
    inv = check_invariants(c)
    assert inv["untouched_changed"] == 0 and inv["targets_outside"] == 0 and inv["lengths_changed"] == 0, inv
    assert inv["sides_swapped"] == 0, inv
    m = correction_measures(c)
    assert m["residual_mm"]["max"] == 0.0 and m["corrections"]["knee"] > 10, m["corrections"]
    if which == "side_kick":
        assert inv["jumps_over_limit"] <= inv["unreachable"] and inv["worst_jump_excess_m"] < 0.005, inv


def test_summary_reports_own_frame_exceedance(balancing_raw):
    m = correction_measures(correct_poses(balancing_raw, TABLE))
    for pair in ("knee", "ankle"):
        e = m["exceeds_own_limit"][pair]
        assert set(e) == {"frames", "max_cm", "mean_cm"} and 0 <= e["mean_cm"] <= e["max_cm"]
    assert m["residual_mm"]["max"] == 0.0  # rotated into K' means inside K'
    assert m["short_of_region"]["frames"] >= 0


@pytest.mark.parametrize("which", ["balancing", "kick"])
def test_online_correction_equals_the_whole_sequence(which, balancing_raw, kick):
    """A live mirror corrects frame by frame; it must give exactly what the whole-clip correction gives, gaps
    (frames without a pose) included."""
    from kitsuke.pose import OnlineCorrector

    poses = (balancing_raw if which == "balancing" else kick).copy()
    valid = poses.valid.copy()
    valid[len(valid) // 3] = False  # a dropped frame restarts K' mid-clip
    poses.valid = valid
    whole = correct_poses(poses, TABLE)
    online = OnlineCorrector(TABLE)
    for f in range(len(poses.positions)):
        got = online(poses.positions[f] if valid[f] else None)
        if not valid[f]:
            assert got is None
            continue
        np.testing.assert_array_equal(got, whole.poses.positions[f])
        np.testing.assert_array_equal(online.status, whole.status[f])
        np.testing.assert_array_equal(online.target, whole.target[f])
    assert whole.rotated.any(), "the clip should need correcting, or this test checks nothing"
