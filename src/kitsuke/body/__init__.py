"""Bodies: mesh + skeleton (kitsuke joint set) + skin weights + capsules; loading, the default body, posing."""

from .body import Body, default_body, load_body
from .capsules import CAPSULE_BONES, Capsule
from .rig import PosedBody, Rig

__all__ = ["CAPSULE_BONES", "Body", "Capsule", "PosedBody", "Rig", "default_body", "load_body"]
