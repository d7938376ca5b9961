"""Import a MakeHuman base mesh with its skeleton and weights, collapsed to the kitsuke joint set.

MakeHuman's default rig (default.mhskel) has 163 bones whose head and tail are each the mean of a group of base.obj
vertices; default_weights.mhw gives per-bone skin weights. We keep the `body` group (the skin; helpers dropped),
place our 23 joints at the corresponding MakeHuman bone heads, and sum each MakeHuman bone's weights into the joint
whose bone it moves with. Used to build the packaged default body (tools/build_default_body.py).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from ..errors import InputError
from ..geometry.obj import read_obj
from ..skeleton import INDEX, JOINTS
from .rig import Rig

#: Our joint <- the MakeHuman bone whose head it sits on (x = L or R; MakeHuman's .L is the person's left, +X).
JOINT_AT_BONE_HEAD: dict[str, str] = {
    "spine": "spine03", "chest": "spine01", "neck": "neck01", "head": "head",
    "x_clavicle": "clavicle.X", "x_shoulder": "upperarm01.X", "x_elbow": "lowerarm01.X", "x_wrist": "wrist.X",
    "x_hip": "upperleg01.X", "x_knee": "lowerleg01.X", "x_ankle": "foot.X",
}  # fmt: skip

#: MakeHuman bones that start a kitsuke bone; every other bone moves with its nearest listed ancestor.
BONE_TO_JOINT: dict[str, str] = {
    "root": "pelvis", "spine05": "pelvis", "pelvis.X": "pelvis",
    "spine03": "spine", "spine01": "chest", "neck01": "neck", "head": "head",
    "clavicle.X": "x_clavicle", "upperarm01.X": "x_shoulder", "lowerarm01.X": "x_elbow", "wrist.X": "x_wrist",
    "upperleg01.X": "x_hip", "lowerleg01.X": "x_knee", "foot.X": "x_ankle",
}  # fmt: skip


def _sided(table: dict[str, str]) -> dict[str, str]:
    out = {}
    for k, v in table.items():
        for side, mh in (("l", "L"), ("r", "R")):
            out[k.replace(".X", f".{mh}").replace("x_", f"{side}_")] = v.replace(".X", f".{mh}").replace(
                "x_", f"{side}_"
            )
    return out


def load_makehuman(
    base_obj: Path, mhskel: Path, mhw: Path, *, scale: float = 0.1
) -> tuple[np.ndarray, np.ndarray, np.ndarray, Rig]:
    """Read MakeHuman files; return (vertices (V, 3) m, faces (F, 3), uv (V, 2), Rig) for the `body` group.

    scale : metres per MakeHuman unit (decimetres).
    """
    data = read_obj(base_obj)
    if "body" not in data.groups:
        raise InputError("no 'body' group: not a MakeHuman base mesh", base_obj)
    all_v = data.vertices * scale
    skel = json.loads(Path(mhskel).read_text())
    bones, groups = skel["bones"], skel["joints"]

    def bone_point(bone: str, end: str) -> np.ndarray:
        return all_v[groups[bones[bone][end]]].mean(axis=0)

    joints = np.zeros((len(JOINTS), 3))
    for ours, mh in _sided(JOINT_AT_BONE_HEAD).items():
        joints[INDEX[ours]] = bone_point(mh, "head")
    # The pelvis is the hip centre, as pose sources (MediaPipe, BVH) define it.
    joints[INDEX["pelvis"]] = 0.5 * (joints[INDEX["l_hip"]] + joints[INDEX["r_hip"]])

    # Skin: keep the body group, renumber.
    body_faces = data.faces[data.face_group == data.groups.index("body")]
    used = np.unique(body_faces)
    remap = np.full(len(all_v), -1)
    remap[used] = np.arange(len(used))
    vertices, faces = all_v[used], remap[body_faces]
    uv = np.zeros((len(all_v), 2))
    if data.uv is not None and data.face_uv is not None:
        uv[data.faces.ravel()] = data.uv[data.face_uv.ravel()]
    uv = uv[used]

    # Weights: each MakeHuman bone -> the kitsuke joint of its nearest mapped ancestor.
    direct = _sided(BONE_TO_JOINT)

    def owner(bone: str) -> str:
        while bone not in direct:
            parent = bones[bone]["parent"]
            if parent is None:
                return "pelvis"
            bone = parent
        return direct[bone]

    mhw_weights = json.loads(Path(mhw).read_text())["weights"]
    weights = np.zeros((len(all_v), len(JOINTS)))
    for bone, pairs in mhw_weights.items():
        if bone not in bones or not pairs:
            continue
        idx, w = np.array(pairs).T
        np.add.at(weights[:, INDEX[owner(bone)]], idx.astype(np.int64), w)
    weights = weights[used]
    # A few MakeHuman weights cross the midline (a vertex of the right shin with 0.005 on the left shin): a left
    # joint must not move the right side. Drop them beyond 2 cm from the midline (the person's left is +X).
    for j, name in enumerate(JOINTS):
        if name[:2] in ("l_", "r_"):
            wrong_side = vertices[:, 0] < -0.02 if name[0] == "l" else vertices[:, 0] > 0.02
            weights[wrong_side, j] = 0.0
    total = weights.sum(axis=1)
    unweighted = total <= 0
    weights[unweighted, INDEX["pelvis"]] = 1.0  # MakeHuman weights every skin vertex; this is a guard only
    weights /= weights.sum(axis=1, keepdims=True)

    # Heel and toe are not MakeHuman joints: place them inside the foot from the skin.
    dominant = weights.argmax(axis=1)
    floor = vertices[:, 1].min()
    for side in ("l", "r"):
        ankle = joints[INDEX[f"{side}_ankle"]]
        foot = vertices[dominant == INDEX[f"{side}_ankle"]]
        back, front = foot[:, 2].min(), foot[:, 2].max()
        # 3 cm above the floor, 3 cm in from the back / 4 cm in from the toe tip: inside the heel and the toes.
        joints[INDEX[f"{side}_heel"]] = [ankle[0], floor + 0.03, back + 0.03]
        tip = foot[foot[:, 2] > front - 0.01]
        joints[INDEX[f"{side}_toe"]] = [tip[:, 0].mean(), floor + 0.02, front - 0.04]
    return vertices, faces, uv, Rig(joints, weights)
