"""Generate the arm's gripper finger mesh (``finger.stl``) once; the STL is committed.

Run from anywhere: ``python models/arm/make_assets.py``. The finger is a convex,
tapered prism (wide at the palm, narrow at the tip) so that MuJoCo's collision
hull and the mesh itself coincide: nothing is silently inflated by the hull.

Frame of the mesh (metres): x across the finger, y its thickness, z along the
finger from the palm (z = 0) to the tip (z = 0.07).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import trimesh


def finger_vertices() -> np.ndarray:
    """(8, 3) vertices of the tapered finger prism, metres."""
    base = [(-0.012, -0.015, 0.0), (0.012, -0.015, 0.0), (0.012, 0.015, 0.0), (-0.012, 0.015, 0.0)]
    tip = [(-0.006, -0.008, 0.07), (0.006, -0.008, 0.07), (0.006, 0.008, 0.07), (-0.006, 0.008, 0.07)]
    return np.array(base + tip, dtype=np.float64)


def main() -> None:
    """Write ``finger.stl`` next to this script."""
    hull = trimesh.Trimesh(finger_vertices(), process=True).convex_hull
    assert hull.is_watertight and hull.is_convex
    out = Path(__file__).resolve().parent / "finger.stl"
    hull.export(out, file_type="stl")
    print(f"wrote {out} ({len(hull.vertices)} vertices, {len(hull.faces)} faces)")


if __name__ == "__main__":
    main()
