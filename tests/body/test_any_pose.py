"""Bodies in any pose are read upright (issue 25): the default body's own rig poses it (T-pose, A-pose, arms down,
legs together, sitting), the posed body is written in other units and axes, and `load_body` must bring it back in
metres, Y up, facing +Z, with its left at +X."""

import json

import numpy as np
import pytest

from kitsuke.body import default_body, load_body
from kitsuke.body.rig import as_matrix
from kitsuke.geometry import TriMesh, save_mesh
from kitsuke.geometry.units import plan_conversion
from kitsuke.skeleton import INDEX

PER_M = {"m": 1.0, "dm": 10.0, "cm": 100.0, "mm": 1000.0, "in": 1 / 0.0254}

# file = R @ kitsuke, for files whose up (the person's head) is along R[:, 1] and whose front is along R[:, 2]
ORIENTATIONS = {
    "y_up": np.eye(3),
    "z_up": np.array([[1.0, 0, 0], [0, 0, -1], [0, 1, 0]]),  # Blender: (x, y, z) -> (x, -z, y)
    "y_down": np.diag([-1.0, -1.0, 1.0]),  # head down: 180 degrees about Z
    "z_down": np.array([[1.0, 0, 0], [0, 0, 1], [0, -1, 0]]),  # (x, y, z) -> (x, z, -y)
    "x_up": np.array([[0.0, -1, 0], [1, 0, 0], [0, 0, 1]]),  # lying on the side, 90 degrees about Z
}


def _turn(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(3,) rotation vector (radians) turning direction a onto direction b."""
    a, b = a / np.linalg.norm(a), b / np.linalg.norm(b)
    axis = np.cross(a, b)
    return axis / np.linalg.norm(axis) * np.arctan2(np.linalg.norm(axis), a @ b)


def _arms(joints: np.ndarray, left: list[float], straight: bool = False) -> dict:
    """Rotations pointing each upper arm along `left` (mirrored for the right arm); `straight` lines the forearm up
    with it (the rest pose bends the elbows forward)."""
    rotations = {}
    for side, sx in (("l", 1.0), ("r", -1.0)):
        shoulder, elbow, wrist = (joints[INDEX[f"{side}_{j}"]] for j in ("shoulder", "elbow", "wrist"))
        target = np.array(left) * [sx, 1.0, 1.0]
        rotations[f"{side}_shoulder"] = _turn(elbow - shoulder, target)
        if straight:  # the elbow's rotation is local to the shoulder's: aim in the shoulder's turned frame
            rotations[f"{side}_elbow"] = _turn(wrist - elbow, as_matrix(rotations[f"{side}_shoulder"]).T @ target)
    return rotations


def _legs_together(joints: np.ndarray) -> dict:
    """Rotations bringing the ankles from 0.22 m to ~0.07 m off the midline (feet a few cm apart)."""
    rotations = {}
    for side, sx in (("l", 1.0), ("r", -1.0)):
        leg = joints[INDEX[f"{side}_ankle"]] - joints[INDEX[f"{side}_hip"]]
        rotations[f"{side}_hip"] = _turn(leg, np.array([-0.045 * sx, -1.0, 0.0]))
    return rotations


# seated: thighs forward (hips flexed 90 degrees about -X), shins down again (knees flexed 90 degrees about +X)
SIT = {f"{side}_{joint}": [sign * np.pi / 2, 0.0, 0.0] for side in "lr" for joint, sign in (("hip", -1), ("knee", 1))}


@pytest.fixture(scope="module")
def rig_body():
    return default_body()


@pytest.fixture(scope="module")
def poses(rig_body):
    """{pose: (V, 3) vertices, metres, Y up, facing +Z, feet on y = 0}."""
    joints = rig_body.rig.joints
    rotations = {
        "t_pose": _arms(joints, [1.0, 0.0, 0.0], straight=True),
        "a_pose": {},
        "arms_down": _arms(joints, [0.12, -1.0, 0.0]),
        "legs_together": {**_legs_together(joints), **_arms(joints, [0.12, -1.0, 0.0])},
        "sitting": SIT,
        "sitting_t_pose": {**SIT, **_arms(joints, [1.0, 0.0, 0.0], straight=True)},
    }
    out = {}
    for name, rot in rotations.items():
        v = rig_body.pose(rotations=rot).vertices
        out[name] = v - [0.0, v[:, 1].min(), 0.0]
    # issue 25's case: arms wider than the body is tall (a T-pose 1.06 times as wide, as 1.77 m across 1.72 m)
    out["t_pose_wide"] = out["t_pose"] * [1.12, 1.0, 1.0]
    return out


@pytest.fixture(scope="module")
def landmarks(rig_body):
    """Vertex indices that the rig's skin weights name: the head, the nose tip, the left and right hands."""
    rig, v = rig_body.rig, rig_body.mesh.vertices
    head = np.flatnonzero(rig.weight_of(["head"]) > 0.9)
    return {
        "head": head,
        "nose": head[np.argmax(v[head, 2])],
        "l_hand": np.flatnonzero(rig.weight_of(["l_wrist"]) > 0.9),
        "r_hand": np.flatnonzero(rig.weight_of(["r_wrist"]) > 0.9),
    }


def _name(axis: np.ndarray) -> str:
    """'+z' for (0, 0, 1) and so on."""
    i = int(np.argmax(np.abs(axis)))
    return ("+" if axis[i] > 0 else "-") + "xyz"[i]


def _write(rig_body, vertices: np.ndarray, unit: str, orientation: str, path):
    """Write a posed body (metres, Y up) in `unit`, turned by ORIENTATIONS[orientation]; returns the path."""
    turned = vertices @ ORIENTATIONS[orientation].T * PER_M[unit]
    return save_mesh(TriMesh(turned, rig_body.mesh.faces), path)


def _assert_upright(body, vertices: np.ndarray, landmarks: dict, atol: float) -> None:
    """`body` (loaded) is the posed `vertices` (V, 3) in metres, Y up, facing +Z, its left at +X."""
    got = body.mesh.vertices
    assert got.shape == vertices.shape
    np.testing.assert_allclose(got, vertices, atol=atol, rtol=0)
    assert abs(body.height_m - np.ptp(vertices[:, 1])) < 0.01  # the extent along up, in metres
    assert np.argmax(got[:, 1]) in set(landmarks["head"])  # the top of the body is the head
    head_centre = got[landmarks["head"]].mean(axis=0)
    assert got[landmarks["nose"], 2] > head_centre[2] + 0.05  # the nose points to +Z
    assert got[landmarks["l_hand"], 0].mean() > 0.1 > -0.1 > got[landmarks["r_hand"], 0].mean()  # left at +X


def test_poses_are_what_they_say(poses):
    """The fixtures themselves: sitting is shorter, the T-poses are wide, issue 25's T-pose is wider than tall."""
    extent = {name: np.ptp(v, axis=0) for name, v in poses.items()}
    assert extent["sitting"][1] == pytest.approx(1.23, abs=0.03)
    assert extent["sitting_t_pose"][0] > extent["sitting_t_pose"][1]
    assert extent["t_pose_wide"][0] > extent["t_pose_wide"][1] + 0.05
    assert extent["legs_together"][0] < 0.55 and extent["arms_down"][0] < 0.55


@pytest.mark.parametrize("orientation", list(ORIENTATIONS))
@pytest.mark.parametrize("unit", list(PER_M))
def test_every_pose_unit_and_axis_is_planned_upright(poses, unit, orientation):
    """The detection alone (no files), over all poses, five units and five orientations."""
    rot = ORIENTATIONS[orientation]
    for name, v in poses.items():
        conv = plan_conversion(v @ rot.T * PER_M[unit])
        found = (conv.up, conv.facing, conv.units)
        assert found == (_name(rot[:, 1]), _name(rot[:, 2]), unit), (name, conv.notes)
        np.testing.assert_allclose(conv.apply(v @ rot.T * PER_M[unit]), v, atol=1e-9)


@pytest.mark.parametrize("orientation", ["y_up", "z_up"])
@pytest.mark.parametrize("unit", ["m", "cm", "mm"])
def test_posed_obj_files_load_upright(tmp_path, rig_body, poses, landmarks, unit, orientation):
    rot = ORIENTATIONS[orientation]
    for name, v in poses.items():
        body = load_body(_write(rig_body, v, unit, orientation, tmp_path / f"{name}.obj"))
        conv = body.conversion
        assert (conv.up, conv.facing, conv.units) == (_name(rot[:, 1]), _name(rot[:, 2]), unit), (name, conv.notes)
        _assert_upright(body, v, landmarks, atol=2e-6)  # OBJ keeps 7 significant digits


@pytest.mark.parametrize(
    ("pose", "unit", "orientation", "suffix"),
    [("sitting", "cm", "z_up", ".ply"), ("t_pose_wide", "mm", "y_down", ".glb"), ("arms_down", "m", "z_down", ".glb")],
)
def test_posed_ply_and_glb_files_load_upright(tmp_path, rig_body, poses, landmarks, pose, unit, orientation, suffix):
    path = _write(rig_body, poses[pose], unit, orientation, tmp_path / f"{pose}{suffix}")
    body = load_body(path)
    assert body.conversion.units == unit
    _assert_upright(body, poses[pose], landmarks, atol=1e-5)  # float32 in the file


def test_body_info_reads_a_wide_t_pose_as_y_up(tmp_path, run_cli, rig_body, poses):
    """Issue 25: a T-pose in metres, Y up, whose arms span more than its height, was read as lying on its side."""
    path = _write(rig_body, poses["t_pose_wide"], "m", "y_up", tmp_path / "t_pose.obj")
    r = run_cli("body", "info", path)
    assert r.code == 0, r.err
    info = json.loads(r.out)
    conversion = info["conversion"]
    assert (conversion["up"], conversion["facing"], conversion["units"]) == ("+y", "+z", "m")
    assert not conversion["applied"]
    assert info["height_m"] == pytest.approx(np.ptp(poses["t_pose_wide"][:, 1]), abs=0.01)


@pytest.mark.parametrize("unit", ["cm", "in"])
def test_a_short_seated_body_keeps_its_units(tmp_path, rig_body, poses, unit):
    """0.95 m seated is 95 cm or 37 inches: where the height alone would say inches, the head's size tells."""
    seated = poses["sitting"] * (0.95 / np.ptp(poses["sitting"][:, 1]))
    body = load_body(_write(rig_body, seated, unit, "z_up", tmp_path / "seated.obj"))
    assert body.conversion.units == unit
    assert body.height_m == pytest.approx(0.95, abs=0.005)


def test_facing_holds_when_the_legs_hold_unequal_vertex_counts(rig_body):
    """A scan or a decimated mesh is not symmetric: a centre (median) of both shins falls inside one leg and reads
    the legs' sideways spread as toes. Here the right leg keeps 3 vertices in 10."""
    right_leg = rig_body.rig.weight_of(["r_hip", "r_knee", "r_ankle", "r_heel", "r_toe"]) > 0.5
    v = rig_body.mesh.vertices
    keep = ~right_leg | (np.arange(len(v)) % 10 < 3)
    for rot in (ORIENTATIONS["y_up"], ORIENTATIONS["z_up"]):
        conv = plan_conversion(v[keep] @ rot.T)
        assert (conv.up, conv.facing) == (_name(rot[:, 1]), _name(rot[:, 2])), conv.notes
