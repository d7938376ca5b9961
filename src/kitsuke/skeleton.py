"""The fixed joint set every part of kitsuke speaks (SPEC §2).

`l_` is the person's own left. With the character facing +Z and Y up, the person's left is +X.
MediaPipe landmarks, BVH skeletons and the body rig all map to this set.
"""

from __future__ import annotations

JOINTS: tuple[str, ...] = (
    "pelvis", "spine", "chest", "neck", "head",
    "l_clavicle", "l_shoulder", "l_elbow", "l_wrist",
    "r_clavicle", "r_shoulder", "r_elbow", "r_wrist",
    "l_hip", "l_knee", "l_ankle", "l_heel", "l_toe",
    "r_hip", "r_knee", "r_ankle", "r_heel", "r_toe",
)  # fmt: skip

#: Parent of each joint in the kinematic tree (the pelvis is the root).
PARENT: dict[str, str | None] = {
    "pelvis": None, "spine": "pelvis", "chest": "spine", "neck": "chest", "head": "neck",
    "l_clavicle": "chest", "l_shoulder": "l_clavicle", "l_elbow": "l_shoulder", "l_wrist": "l_elbow",
    "r_clavicle": "chest", "r_shoulder": "r_clavicle", "r_elbow": "r_shoulder", "r_wrist": "r_elbow",
    "l_hip": "pelvis", "l_knee": "l_hip", "l_ankle": "l_knee", "l_heel": "l_ankle", "l_toe": "l_ankle",
    "r_hip": "pelvis", "r_knee": "r_hip", "r_ankle": "r_knee", "r_heel": "r_ankle", "r_toe": "r_ankle",
}  # fmt: skip

INDEX: dict[str, int] = {name: i for i, name in enumerate(JOINTS)}

#: Parent index per joint, -1 for the root; parents always come before their children in JOINTS.
PARENT_INDEX: tuple[int, ...] = tuple(-1 if PARENT[j] is None else INDEX[PARENT[j]] for j in JOINTS)  # type: ignore[index]

CHILDREN: dict[str, tuple[str, ...]] = {j: tuple(c for c in JOINTS if PARENT[c] == j) for j in JOINTS}

#: Bones as (start joint, end joint) pairs: every joint with its parent.
BONES: tuple[tuple[str, str], ...] = tuple((PARENT[j], j) for j in JOINTS if PARENT[j] is not None)  # type: ignore[misc]


def descendants(joint: int) -> list[int]:
    """The indices of the joints below `joint` in the tree (its children, theirs, ...; not itself), in order."""
    out = []
    for j in range(len(JOINTS)):
        p = PARENT_INDEX[j]
        while p >= 0 and p != joint:
            p = PARENT_INDEX[p]
        if p == joint:
            out.append(j)
    return out


def joint_index(name: str) -> int:
    """Index of a joint in JOINTS; ValueError naming the valid joints if unknown."""
    try:
        return INDEX[name]
    except KeyError:
        raise ValueError(f"unknown joint {name!r}; joints are: {', '.join(JOINTS)}") from None


def mirror_name(name: str) -> str:
    """The joint on the other side (l_knee <-> r_knee); centre joints map to themselves."""
    if name.startswith("l_"):
        return "r_" + name[2:]
    if name.startswith("r_"):
        return "l_" + name[2:]
    return name
