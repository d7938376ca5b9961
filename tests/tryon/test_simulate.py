"""The kimono simulated on a body moved by poses: the lead-in, the quality the simulation holds, the report that
says what it misses, the animated GLB, the video, and honest failures."""

from __future__ import annotations

import dataclasses
import json
import shutil
import struct
from pathlib import Path

import numpy as np
import pytest

from kitsuke.body import default_body
from kitsuke.body.animate import animate, posed_vertices
from kitsuke.body.capsules import capsule_segments
from kitsuke.body.skinning import skin
from kitsuke.dressing.export import write_garment_obj
from kitsuke.errors import ComputationError
from kitsuke.metrics import QualityTargets, penetration, strain
from kitsuke.pose import PoseSequence, load_bvh, write_poses
from kitsuke.skeleton import INDEX
from kitsuke.tryon import (
    KimonoSimulator,
    SimulationSettings,
    cloth_model,
    default_simulation_kimono,
    placed_at_rest,
    simulate_kimono,
    with_lead_in,
)
from kitsuke.tryon.outputs import write_kimono_glb

from ..conftest import GLTF_VALIDATOR, gltf_report

ROOT = Path(__file__).resolve().parents[2]
WALK = ROOT / "tests" / "data" / "pose" / "cmu_131_01_start_walk_stop.bvh"
SHIRT = ROOT / "tests" / "data" / "pattern" / "shirt_mean_specification.json"
SHORT = SimulationSettings(hold_s=0.1, blend_s=0.3)


@pytest.fixture(scope="module")
def body():
    return default_body()


@pytest.fixture(scope="module")
def kimono(body):
    return default_simulation_kimono(body)


@pytest.fixture(scope="module")
def walk():
    return load_bvh(WALK, stride=4, max_frames=12)


@pytest.fixture(scope="module")
def motion(body, kimono, walk):
    return simulate_kimono(walk, body=body, garment=kimono, settings=SHORT)


def _glb_json(path: Path) -> tuple[dict, bytes]:
    data = path.read_bytes()
    n = struct.unpack_from("<I", data, 12)[0]
    doc = json.loads(data[20 : 20 + n])
    return doc, data[20 + n + 8 :]


def _accessor(doc: dict, binary: bytes, index: int) -> np.ndarray:
    acc = doc["accessors"][index]
    view = doc["bufferViews"][acc["bufferView"]]
    width = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}[acc["type"]]
    raw = np.frombuffer(binary, "<f4", acc["count"] * width, view["byteOffset"])
    return raw.reshape(acc["count"], width)


def test_the_clip_starts_where_the_kimono_was_dressed_after_a_smooth_lead_in(body, walk):
    anim = animate(body, walk)
    rest = body.rig.joints
    placed = placed_at_rest(anim, rest)
    pelvis = INDEX["pelvis"]
    np.testing.assert_allclose(placed.joints[0, pelvis, [0, 2]], rest[pelvis, [0, 2]], atol=1e-9)
    forward = placed.rotations[0, pelvis] @ [0.0, 0.0, 1.0]
    assert abs(np.degrees(np.arctan2(forward[0], forward[2]))) < 1e-6  # facing +Z, as the dressed body
    # moved and turned as a whole: distances between joints are the clip's
    d0 = np.linalg.norm(anim.joints[:, :, None] - anim.joints[:, None], axis=-1)
    d1 = np.linalg.norm(placed.joints[:, :, None] - placed.joints[:, None], axis=-1)
    np.testing.assert_allclose(d1, d0, atol=1e-9)

    full, n_lead = with_lead_in(anim, rest, hold_s=0.2, blend_s=0.5)
    assert n_lead == 21 and full.n_frames == anim.n_frames + n_lead
    np.testing.assert_allclose(full.joints[:6], np.broadcast_to(rest, (6,) + rest.shape), atol=1e-12)
    np.testing.assert_allclose(full.rotations[n_lead - 1], placed.rotations[0], atol=1e-9)
    np.testing.assert_allclose(full.joints[n_lead - 1], placed.joints[0], atol=1e-9)
    step = np.linalg.norm(np.diff(full.joints[: n_lead + 1], axis=0), axis=-1).max()
    assert step < 0.06  # no joint moves more than 6 cm a frame in the lead-in
    assert np.all(np.diff(full.times) > 0)


def test_held_at_rest_the_simulated_kimono_stays_as_it_was_dressed(body, kimono):
    """A stable solver keeps a dressed kimono on a still body as dressed: over 1.5 s at rest its mean strain stays
    within the dressing's target and its 99th percentile barely grows, nothing goes inside, the obi holds, and it
    settles (hanging, it sinks about a centimetre, then stays)."""
    anim = animate(body, load_bvh(WALK, stride=4, max_frames=1))
    sim = KimonoSimulator(body, kimono, anim.weights)
    start = sim.state.positions.copy()
    s0 = strain(start, sim.model.edges, sim.model.rest_lengths)
    rest_rot = np.tile(np.eye(3), (len(body.rig.joints), 1, 1))
    for _ in range(30):
        sim.advance(rest_rot, body.rig.joints, 1 / 30)
    before = sim.state.positions.copy()
    for _ in range(15):
        skin_v = sim.advance(rest_rot, body.rig.joints, 1 / 30)
    x = sim.state.positions
    s1 = strain(x, sim.model.edges, sim.model.rest_lengths)
    # the sleeves settle (the dressing's statics are not the solver's): the mean may grow, within the dressing's
    # own target (0.35 -> 0.75 % in a fresh environment of 2026-11-27, just under 0.75 % before: chaotic)
    assert s1.mean <= QualityTargets().mean_strain
    assert np.percentile(s1.per_edge, 99) <= np.percentile(s0.per_edge, 99) + 0.02
    assert penetration(x, body.mesh, threshold_m=0.002).count == 0
    assert np.mean(x[:, 1] - start[:, 1]) > -0.02
    assert np.linalg.norm(x - before, axis=1).mean() < 0.003  # settled: under 3 mm in the last half second
    held = sim.moving.hold.vertices
    np.testing.assert_allclose(x[held], start[held], atol=1e-6)
    assert skin_v.shape == body.mesh.vertices.shape


def test_the_kimono_follows_the_walking_body(body, motion):
    """Over the corrected walk: the obi stays on the waist, the kimono on the body (nothing farther than its hanging
    sleeves reach), and the cloth is not torn. (The targets, max strain 10 % and nothing 5 mm inside on every frame,
    are not met yet: the report says so, next test.)"""
    model = cloth_model(motion.garment)
    held = None
    for f in range(len(motion.quality)):
        x = motion.positions[f].astype(np.float64)
        assert np.isfinite(x).all()
        skin_v = posed_vertices(body, motion.animation, f)
        s = strain(x, model.edges, model.rest_lengths)
        assert s.mean < 0.03 and np.percentile(s.per_edge, 99) < 0.25, f
        pen = penetration(x, type(body.mesh)(skin_v, body.mesh.faces), threshold_m=0.005)
        assert pen.count <= 0.01 * len(x) and pen.deepest_mm < 30, f
        if held is None:
            from kitsuke.dressing.kimono import obi_band

            low, high = obi_band(body)
            held = np.flatnonzero((x[:, 1] >= low) & (x[:, 1] <= high))
        waist = skin_v[:, 1]
        assert np.all(x[held, 1] > waist.min()) and np.all(x[held, 1] < waist.max())
    pelvis_path = motion.animation.joints[:, INDEX["pelvis"]]
    cloth_centre = motion.positions.mean(axis=1)
    assert np.abs(cloth_centre[:, [0, 2]] - pelvis_path[:, [0, 2]]).max() < 0.15  # it goes where the body goes


def test_the_report_gives_every_frame_and_says_what_misses(motion):
    s = motion.summary()
    assert s["frames"] == len(s["per_frame"]) == motion.positions.shape[0]
    assert s["lead_in_frames"] == motion.n_lead == 12 and s["clip_frames"] == 12 and s["corrected"]
    targets = SHORT.targets
    for q in s["per_frame"]:
        assert q["ok"] == (q["penetration_count"] == 0 and q["strain_max"] <= targets.max_strain)
        assert q["step_s"] > 0
    assert s["frames_within_targets"] == sum(q["ok"] for q in s["per_frame"] if not q["lead_in"])
    clip = [q for q in s["per_frame"] if not q["lead_in"]]
    assert s["worst"]["strain_max"] == max(q["strain_max"] for q in clip)
    assert clip[0]["time_s"] == 0.0


def test_the_animated_glb_plays_the_body_and_the_kimono(tmp_path, body, motion):
    path = write_kimono_glb(motion, body, tmp_path / "kimono.glb")
    doc, binary = _glb_json(path)
    assert [m["name"] for m in doc["meshes"]] == ["body", "kimono"]
    prim = doc["meshes"][1]["primitives"][0]
    n = motion.positions.shape[0]
    assert len(prim["targets"]) == n and "TEXCOORD_0" in prim["attributes"]
    assert doc["textures"] and doc["images"][0]["mimeType"] == "image/png"
    anim = doc["animations"][0]
    weights = [c for c in anim["channels"] if c["target"]["path"] == "weights"]
    assert len(weights) == 1
    w = _accessor(doc, binary, anim["samplers"][weights[0]["sampler"]]["output"]).reshape(n, n)
    np.testing.assert_array_equal(w, np.eye(n))  # frame k shows target k
    from kitsuke.tryon.outputs import kimono_mesh

    _, index = kimono_mesh(motion, textured=False)
    base = _accessor(doc, binary, prim["attributes"]["POSITION"])
    k = n - 1
    shown = base + _accessor(doc, binary, prim["targets"][k]["POSITION"])
    np.testing.assert_allclose(shown, motion.positions[k][index], atol=1e-5)
    if GLTF_VALIDATOR.exists() and shutil.which("node"):
        report = gltf_report(path)
        assert report["errors"] == 0 and report["warnings"] == 0, report["messages"]


def test_a_kimono_that_leaves_the_body_is_a_failure(body, kimono):
    anim = animate(body, load_bvh(WALK, stride=4, max_frames=1))
    sim = KimonoSimulator(body, kimono, anim.weights)
    rest_rot = np.tile(np.eye(3), (len(body.rig.joints), 1, 1))
    sim.advance(rest_rot, body.rig.joints, 1 / 30)
    # the body stands a metre to the side, the obi let go, and the cloth forgets where the skin was
    far = body.rig.joints + [1.0, 0.0, 0.0]
    ends, _ = capsule_segments(body.capsules, far, rest_rot)
    sim.moving.hold = None
    sim.moving.move_to(ends, skin(body.mesh.vertices, anim.weights, body.rig.joints, rest_rot, far))
    sim.state.contacts.face[:] = -1
    with pytest.raises(ComputationError, match="frame 1: the kimono left the body"):
        sim.advance(rest_rot, far, 1 / 30)


def test_a_diverging_simulation_names_the_frame(body, kimono):
    anim = animate(body, load_bvh(WALK, stride=4, max_frames=1))
    sim = KimonoSimulator(body, kimono, anim.weights)
    rest_rot = np.tile(np.eye(3), (len(body.rig.joints), 1, 1))
    sim.advance(rest_rot, body.rig.joints, 1 / 30)
    sim.state.positions[np.argmax(sim.state.positions[:, 1])] += [0.0, 1e6, 0.0]
    with pytest.raises(ComputationError, match="frame 1") as e:
        sim.advance(rest_rot, body.rig.joints, 1 / 30)
    assert e.value.stage == "simulation"


@pytest.mark.slow
def test_kimono_simulate_writes_glb_video_and_report(run_cli, tmp_path, kimono):
    import imageio_ffmpeg

    garment = write_garment_obj(kimono, tmp_path / "dressed.obj")
    out = tmp_path / "walk.glb"
    r = run_cli(
        "kimono", "simulate", "--poses", WALK, "--stride", "4", "--max-frames", "6", "--garment", garment,
        "--hold", "0.1", "--blend", "0.2", "-o", out, "--video", tmp_path / "walk.mp4",
        "--report", tmp_path / "walk.json", "--png", tmp_path / "walk.png",
    )  # fmt: skip
    assert r.code == 0, r.err
    summary = json.loads(r.out)
    report = json.loads((tmp_path / "walk.json").read_text())
    assert summary["frames"] == report["frames"] == 6 + 9 == len(report["per_frame"])
    if summary["frames_within_targets"] < summary["clip_frames"]:
        assert "miss the targets" in r.err
    reader = imageio_ffmpeg.read_frames(str(tmp_path / "walk.mp4"))
    meta = next(reader)
    assert meta["codec"] == "h264" and sum(1 for _ in reader) == 15
    assert (tmp_path / "walk.png").stat().st_size > 10_000


def _poses_file(tmp_path: Path, name: str, positions: np.ndarray, valid: np.ndarray) -> Path:
    n = len(positions)
    seq = PoseSequence(positions, valid, np.arange(n) / 30.0, 30.0, {"kind": "poses"})
    return write_poses(seq, tmp_path / name)


def test_bad_inputs_exit_2_with_one_line(run_cli, tmp_path, walk):
    out = tmp_path / "out.glb"
    out.write_bytes(b"keep")
    nobody = _poses_file(tmp_path, "nobody.json", np.full((3, 23, 3), np.nan), np.zeros(3, bool))
    r = run_cli("kimono", "simulate", "--poses", nobody, "-o", out)
    assert r.code == 2 and "no frame with a person" in r.err and len(r.err.strip().splitlines()) == 1
    r = run_cli("kimono", "simulate", "--poses", WALK, "--pattern", SHIRT, "-o", out)
    assert r.code == 2 and "not a kimono" in r.err and str(SHIRT) in r.err
    r = run_cli("kimono", "simulate", "--poses", WALK, "--substeps", "0", "-o", out)
    assert r.code == 2 and "substeps" in r.err
    r = run_cli("kimono", "simulate", "--poses", tmp_path / "missing.bvh", "-o", out)
    assert r.code == 2 and "not found" in r.err
    r = run_cli("kimono", "simulate", "--poses", WALK, "--hold", "-1", "-o", out)
    assert r.code == 2 and "lead-in" in r.err and "dressing" not in r.err  # refused before the kimono is dressed
    assert out.read_bytes() == b"keep"


def test_poses_with_nan_are_refused(body, kimono, walk):
    from kitsuke.errors import InputError

    bad = dataclasses.replace(walk, positions=walk.positions.copy())
    bad.positions[3, 5, 0] = np.nan
    with pytest.raises(InputError, match="frame 3"):
        simulate_kimono(bad, body=body, garment=kimono, settings=SHORT)
