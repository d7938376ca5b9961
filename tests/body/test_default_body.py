import igl
import numpy as np
import pytest

from kitsuke.body import CAPSULE_BONES, default_body
from kitsuke.body.capsules import segment_distance
from kitsuke.errors import InputError
from kitsuke.skeleton import INDEX, JOINTS


@pytest.fixture(scope="module")
def body():
    return default_body()


def inside(body, points):
    return igl.winding_number(body.mesh.vertices, body.mesh.faces, np.asarray(points, dtype=np.float64)) > 0.5


def test_default_body_is_a_clean_standing_person(body):
    assert body.rigged
    assert body.mesh.n_vertices == 13380 and body.mesh.n_faces == 26756
    assert body.height_m == pytest.approx(1.666, abs=0.005)
    assert body.mesh.vertices[:, 1].min() == pytest.approx(0.0, abs=1e-9)  # feet on the floor
    from kitsuke.geometry import clean_mesh

    _, check = clean_mesh(body.mesh)
    assert check.watertight
    # Facing +Z: the toes are in front of the heels; the person's left (+X) has the l_ joints.
    j = body.rig.joints
    assert (j[INDEX["l_toe"], 2] > j[INDEX["l_heel"], 2]) and (j[INDEX["l_hip"], 0] > 0 > j[INDEX["r_hip"], 0])


def test_every_joint_lies_inside_the_body(body):
    assert inside(body, body.rig.joints).all(), [n for n, ok in zip(JOINTS, inside(body, body.rig.joints)) if not ok]


def test_skeleton_is_symmetric_and_ordered(body):
    j = body.rig.joints
    for name in JOINTS:
        if name.startswith("l_"):
            np.testing.assert_allclose(j[INDEX[name]] * [-1, 1, 1], j[INDEX["r_" + name[2:]]], atol=2e-3)
    heights = [j[INDEX[n], 1] for n in ("l_ankle", "l_knee", "l_hip", "spine", "chest", "neck", "head")]
    assert heights == sorted(heights)


def test_weights_are_partition_of_unity_and_local(body):
    w = body.rig.weights
    np.testing.assert_allclose(w.sum(axis=1), 1.0, atol=1e-9)
    # Vertices low on the left shin are driven by the left knee only.
    v = body.mesh.vertices
    shin = (v[:, 0] > 0.1) & (v[:, 1] > 0.15) & (v[:, 1] < 0.35)
    assert w[shin, INDEX["l_knee"]].mean() > 0.9


def test_weight_of_a_bone_group(body):
    """`Rig.weight_of` sums skin weights per vertex: all joints give 1; the torso's bones carry the belly at the
    waist and not the hands hanging beside it."""
    rig = body.rig
    np.testing.assert_allclose(rig.weight_of(JOINTS), 1.0)
    torso = rig.weight_of(("pelvis", "spine", "chest"))
    v = body.mesh.vertices
    waist = rig.joints[INDEX["spine"]]
    belly = np.argmin(np.linalg.norm(v - (waist + [0.0, 0.0, 0.15]), axis=1))
    hand = np.argmin(np.linalg.norm(v - rig.joints[INDEX["l_wrist"]], axis=1))
    assert torso[belly] > 0.9 and torso[hand] < 0.05
    with pytest.raises(ValueError):
        rig.weight_of(("no_such_joint",))


def test_bending_left_knee_moves_left_shin_only(body):
    posed = body.pose(rotations={"l_knee": [np.pi / 2, 0.0, 0.0]})
    v0, v1 = body.mesh.vertices, posed.vertices
    moved = np.linalg.norm(v1 - v0, axis=1)
    left_shin = body.rig.weights[:, INDEX["l_knee"]] > 0.99
    right_leg = (v0[:, 0] < -0.05) & (v0[:, 1] < 0.8)
    assert moved[left_shin].min() > 0.02
    assert moved[right_leg].max() < 1e-12  # untouched up to rounding in the weight blend
    # The left ankle swung back (-Z) and up, by the shin's length: a 90-degree bend.
    ka, kb = body.rig.joints[INDEX["l_knee"]], body.rig.joints[INDEX["l_ankle"]]
    a = posed.joints[INDEX["l_ankle"]]
    shin = np.linalg.norm(kb - ka)
    assert a[2] < ka[2] - 0.9 * shin
    assert abs(a[1] - ka[1]) < 0.1 * shin
    # Bone lengths never change.
    for child in range(1, len(JOINTS)):
        from kitsuke.skeleton import PARENT_INDEX

        p = PARENT_INDEX[child]
        rest = np.linalg.norm(body.rig.joints[child] - body.rig.joints[p])
        assert np.linalg.norm(posed.joints[child] - posed.joints[p]) == pytest.approx(rest, abs=1e-12)


def swing(body, joint, child, angle_rad):
    """A rotation of `joint` about an axis perpendicular to its bone (no twist): positions can express it."""
    bone = body.rig.joints[INDEX[child]] - body.rig.joints[INDEX[joint]]
    axis = np.cross(bone, [0.3, 0.2, 1.0])
    return axis / np.linalg.norm(axis) * angle_rad


def hinge(body, root, joint, child, angle_rad):
    """A bend of `joint` about its hinge (the normal of the rest pose's bend: the default body's elbows are bent)."""
    j = body.rig.joints
    axis = np.cross(j[INDEX[joint]] - j[INDEX[root]], j[INDEX[child]] - j[INDEX[joint]])
    return axis / np.linalg.norm(axis) * angle_rad


def test_pose_from_positions_reproduces_a_rotation_pose(body):
    rotations = {
        "l_hip": swing(body, "l_hip", "l_knee", -0.6),
        "r_shoulder": swing(body, "r_shoulder", "r_elbow", 0.5),
        "l_elbow": hinge(body, "l_shoulder", "l_elbow", "l_wrist", 0.7),
    }
    target = body.pose(rotations=rotations)
    again = body.pose(positions=target.joints)
    np.testing.assert_allclose(again.joints, target.joints, atol=1e-9)
    np.testing.assert_allclose(again.vertices, target.vertices, atol=1e-9)
    # Named targets: only the left leg given; the rest keeps its rest direction.
    leg = {n: target.joints[INDEX[n]] for n in ("pelvis", "l_hip", "l_knee")}
    part = body.pose(positions=leg)
    np.testing.assert_allclose(part.joints[INDEX["l_knee"]], target.joints[INDEX["l_knee"]], atol=1e-9)


def test_a_bend_off_the_hinge_turns_the_upper_arm(body):
    """An elbow bent sideways from positions: the shoulder twists so that the elbow bends about its own hinge (the
    skin of the elbow does not twist), and the joints still land on their targets."""
    target = body.pose(rotations={"l_elbow": swing(body, "l_elbow", "l_wrist", 0.9)})
    again = body.pose(positions=target.joints)
    np.testing.assert_allclose(again.joints, target.joints, atol=1e-9)
    upper = again.joints[INDEX["l_elbow"]] - again.joints[INDEX["l_shoulder"]]
    fore = again.joints[INDEX["l_wrist"]] - again.joints[INDEX["l_elbow"]]
    rest = body.rig.joints
    hinge_now = again.rotations[INDEX["l_shoulder"]] @ np.cross(
        rest[INDEX["l_elbow"]] - rest[INDEX["l_shoulder"]], rest[INDEX["l_wrist"]] - rest[INDEX["l_elbow"]]
    )
    bend_normal = np.cross(upper, fore)
    cos = abs(hinge_now @ bend_normal) / (np.linalg.norm(hinge_now) * np.linalg.norm(bend_normal))
    assert cos > 0.999


def test_rest_pose_is_identity(body):
    posed = body.pose()
    np.testing.assert_allclose(posed.vertices, body.mesh.vertices, atol=1e-12)


def test_capsules_lie_inside_the_limbs(body):
    ends, radii = body.capsule_segments()
    assert len(ends) == len(CAPSULE_BONES)
    # Posed capsules follow the bones: bend the left elbow and the forearm capsule turns with it.
    posed = body.pose(rotations={"l_elbow": swing(body, "l_elbow", "l_wrist", 1.0)})
    posed_ends, _ = body.capsule_segments(posed)
    k = [c[0] for c in CAPSULE_BONES].index("l_forearm")
    rest_len = np.linalg.norm(ends[k, 1] - ends[k, 0])
    assert np.linalg.norm(posed_ends[k, 1] - posed_ends[k, 0]) == pytest.approx(rest_len, rel=0.05)
    assert np.linalg.norm(posed_ends[k, 1] - ends[k, 1]) > 0.1
    rng = np.random.default_rng(0)
    for (a, b), (ra, rb), (name, _, _) in zip(ends, radii, CAPSULE_BONES):
        assert 0.005 < min(ra, rb) and max(ra, rb) < 0.15, name
        # Points on the capsule's surface along the bone (10-90 %) are inside the body.
        t = rng.uniform(0.1, 0.9, 128)
        r = ra + (rb - ra) * t
        axis = (b - a) / np.linalg.norm(b - a)
        perp = np.cross(axis, rng.normal(size=(128, 3)))
        perp /= np.linalg.norm(perp, axis=1, keepdims=True)
        pts = a + t[:, None] * (b - a) + r[:, None] * perp
        assert inside(body, pts).mean() > 0.95, name
        d, _ = segment_distance(pts, a, b)
        np.testing.assert_allclose(d, r, atol=1e-9)
    # Limbs taper toward the distal joint.
    k = [c[0] for c in CAPSULE_BONES].index("l_thigh")
    assert radii[k, 0] > radii[k, 1]


def test_pose_bad_input(body):
    with pytest.raises(ValueError, match="unknown joint"):
        body.pose(rotations={"l_knee2": [0, 0, 0]})
    with pytest.raises(ValueError, match="rotation"):
        body.pose(rotations={"l_knee": [0, 0]})


def test_unrigged_body_cannot_be_posed():
    from kitsuke.body import Body

    b = Body(mesh=default_body().mesh, source="x.obj")
    with pytest.raises(InputError, match="no rig"):
        b.pose()
