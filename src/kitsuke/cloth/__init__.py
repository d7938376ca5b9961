"""Cloth core: the static model, the relaxation of the paper, edge-length restoration, an energy polish that caps
strain, Skin-style body collision with capsule bones, adaptive sqrt(3) subdivision, and untangling of folded
triangles.

Typical use::

    model = ClothModel.from_corners(faces, rest_corners)        # (F, 3), (F, 3, 2) metres
    state = ClothState.new(model, positions, pinned=pins)       # (V, 3) metres
    collider = BodyCollider.from_body(default_body())
    relax(model, state, collider, iterations=50)                 # in place

`relax` is not physics: vertices move directly towards their triangles' rest shapes, hinges open, gravity is a
small move down, and collision pushes the cloth out of the body. Constants live in `ClothParams`.

`step(model, state, body, dt)` is: XPBD dynamics on the same model and state (with velocities) against a moving
`MovingBody`; constants in `DynamicsParams` (see `_dynamics.py`). `sew(model, state, collider)` closes open seams
with that solver, weightless, a little each frame.
"""

from ._collide import (
    BodyCollider,
    CollisionStats,
    LayerPlanes,
    collide,
    keep_layers,
    layer_planes,
    sweep,
    track,
    vertex_active,
)
from ._dynamics import DynamicsData, DynamicsParams, MovingBody, SkinHold, dynamics_data, step
from ._lengths import LengthStats, restore_lengths
from ._model import ClothModel, ClothParams, ClothState, Contacts, locality_order
from ._polish import PolishStats, RefinedPolish, bending_stencil, compile_polish, polish, polish_refined
from ._precompile import precompile_in_background
from ._relax import RelaxStats, relax
from ._sew import SewStats, sew
from ._shapes import grid_sheet, grid_tube, hugging_tube, triangle_frames
from ._subdivide import Refinement, colliding_edges, refine, sqrt3_split
from ._tethers import Tethers
from ._untangle import UntangleStats, folded_faces, grow_region, untangle

__all__ = [
    "BodyCollider",
    "DynamicsData",
    "DynamicsParams",
    "SkinHold",
    "dynamics_data",
    "step",
    "sew",
    "ClothModel",
    "ClothParams",
    "ClothState",
    "CollisionStats",
    "Contacts",
    "LayerPlanes",
    "LengthStats",
    "MovingBody",
    "PolishStats",
    "RefinedPolish",
    "Refinement",
    "RelaxStats",
    "SewStats",
    "Tethers",
    "UntangleStats",
    "collide",
    "compile_polish",
    "precompile_in_background",
    "folded_faces",
    "grow_region",
    "keep_layers",
    "layer_planes",
    "colliding_edges",
    "bending_stencil",
    "grid_sheet",
    "grid_tube",
    "hugging_tube",
    "locality_order",
    "polish",
    "polish_refined",
    "refine",
    "relax",
    "restore_lengths",
    "sqrt3_split",
    "sweep",
    "track",
    "triangle_frames",
    "untangle",
    "vertex_active",
]
