"""Build src/kitsuke/assets/body/default_body.npz from MakeHuman's CC0 files.

    python tools/build_default_body.py ../shared/data/bodies/makehuman

Reads base.obj (group `body`), default.mhskel and default_weights.mhw; collapses the rig to the kitsuke joint set
(kitsuke.body.makehuman); converts decimetres to metres and puts the feet on y = 0. Weights are stored as float32,
rounded to 1e-4 and renormalised, which keeps the file small.
"""

import sys
from pathlib import Path

import numpy as np

from kitsuke.body.makehuman import load_makehuman


def main() -> None:
    src = Path(sys.argv[1] if len(sys.argv) > 1 else "../shared/data/bodies/makehuman")
    vertices, faces, uv, rig = load_makehuman(src / "base.obj", src / "default.mhskel", src / "default_weights.mhw")
    lift = -vertices[:, 1].min()
    vertices[:, 1] += lift
    joints = rig.joints + [0.0, lift, 0.0]
    w = np.round(rig.weights, 4)
    w /= w.sum(axis=1, keepdims=True)
    out = Path(__file__).resolve().parents[1] / "src/kitsuke/assets/body/default_body.npz"
    np.savez_compressed(
        out,
        vertices=vertices,
        faces=faces.astype(np.int32),
        uv=uv,
        joints=joints,
        weights=w.astype(np.float32),
    )
    print(
        f"wrote {out} ({out.stat().st_size / 1e6:.2f} MB): {len(vertices)} vertices, {len(faces)} faces, "
        f"height {np.ptp(vertices[:, 1]):.3f} m"
    )


if __name__ == "__main__":
    main()
