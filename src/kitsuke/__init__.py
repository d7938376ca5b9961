"""kitsuke: put garments on 3D people.

Subpackages, each one concern (data flows top to bottom):

- `kitsuke.geometry`  triangle meshes: loading, validation, units and axes
- `kitsuke.body`      Body = mesh + skeleton + skin weights + capsules; the default body; posing
- `kitsuke.pattern`   sewing patterns: pieces, seams, importers/exporters, kimono generator, triangulation
- `kitsuke.cloth`     cloth model and state, relaxation, Skin-style body/capsule collision, adaptive sqrt(3) subdivision
- `kitsuke.metrics`   quality measures: penetration, strain, seam gap, inverted triangles, reports
- `kitsuke.render`    offscreen PNG renders of meshes
- `kitsuke.pose`      poses from video/camera/BVH/JSON, filtering, kimono posture correction

Import the subpackage you need; `import kitsuke` itself is light.
"""

__version__ = "0.1.0"
