"""shape_distance on the tunnel pair (wall box, ball sphere, overlapping) and its pose checks, best of 7 x 5000 calls.

PYTHONPATH=<tree> python docs/notes/issue-12-tunnel-3/shape_distance.py
"""
import time, numpy as np, mujoco, monitor
from monitor.geometry.distance import shape_distance, _check_pose, _core
m = mujoco.MjModel.from_xml_path("models/tunnel/scene.xml")
sc = monitor.Scene.from_model(m)
ga, gb = sc.geom("wall"), sc.geom("ball")
R = np.eye(3); pa = np.zeros(3); pb = np.array([-0.012, 0, 0])
def T(f, n=5000):
    r = []
    for _ in range(7):
        s = time.perf_counter()
        for _ in range(n): f()
        r.append((time.perf_counter() - s) / n * 1e6)
    return round(min(r), 2)
print("shape_distance", T(lambda: shape_distance(ga.shape, (R, pa), gb.shape, (R, pb))))
print("_check_pose x2", T(lambda: (_check_pose((R, pa), "X_a"), _check_pose((R, pb), "X_b"))))
print("_core x2", T(lambda: (_core(ga.shape, "a"), _core(gb.shape, "b"))))
print(shape_distance(ga.shape, (R, pa), gb.shape, (R, pb)))
