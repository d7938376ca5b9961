"""kitsuke: put garments on 3D people.

Subpackages, each one concern (data flows top to bottom):

- `kitsuke.geometry`  triangle meshes: loading, validation, units and axes
- `kitsuke.body`      Body = mesh + skeleton + skin weights + capsules; the default body; posing
- `kitsuke.pattern`   sewing patterns: pieces, seams, importers/exporters, kimono generator, triangulation
- `kitsuke.cloth`     cloth model and state, relaxation, Skin-style body/capsule collision, adaptive sqrt(3) subdivision
- `kitsuke.metrics`   quality measures: penetration, strain, seam gap, inverted triangles, reports
- `kitsuke.render`    offscreen PNG renders of meshes
- `kitsuke.dressing`  strokes, wrap, re-wrap, drag with pins, dressed-garment files
- `kitsuke.pose`      poses from video/camera/BVH/JSON, filtering, kimono posture correction

Import the subpackage you need; `import kitsuke` itself is light.
"""

import os as _os

# numba's parallel kernels run on OpenMP threads, which by default spin while they wait: on a machine whose cores
# are busy (2 cores, another process) one drag update took 190 ms instead of 14 ms. Passive waiting costs nothing
# measurable on an idle machine. A user's own setting wins; it must be set before the OpenMP runtime starts.
_os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

__version__ = "0.1.0"
