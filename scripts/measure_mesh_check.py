"""Cost of the trimesh mesh check in Scene construction (first time vs cached).

Usage: PYTHONPATH=. python scripts/measure_mesh_check.py   (docs/notes/issue-16.md, "Leftovers (h16b)")
"""
import sys, time, warnings; sys.path.insert(0, "tests")
t=time.perf_counter(); import trimesh; print(f"import trimesh {time.perf_counter()-t:.3f}s")
import mujoco, numpy as np
import monitor.scene as sc
from monitor._paths import scene_path
from test_scene_mesh import _model, _prism, L_XY, H
warnings.simplefilter("ignore")
for name, m in (("L", _model(*_prism(L_XY, H))), ("arm", mujoco.MjModel.from_xml_path(str(scene_path("arm"))))):
    g = [i for i in range(m.ngeom) if m.geom_type[i] == mujoco.mjtGeom.mjGEOM_MESH][0]
    ts = []; tc = []
    for _ in range(7):
        sc._MESH_CHECKS.clear(); t = time.perf_counter(); sc._check_mesh(m, int(m.geom_dataid[g]), g); ts.append(time.perf_counter() - t)
        t = time.perf_counter(); sc._check_mesh(m, int(m.geom_dataid[g]), g); tc.append(time.perf_counter() - t)
    print(f"{name}: check {np.median(ts)*1e6:.0f} us, cached {np.median(tc)*1e6:.0f} us (median of 7)")
    ts = []
    for _ in range(5):
        t = time.perf_counter(); sc.Scene.from_model(m); ts.append(time.perf_counter() - t)
    print(f"{name}: Scene.from_model (mesh cached) {np.median(ts)*1e3:.1f} ms")
