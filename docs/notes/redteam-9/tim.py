import time, numpy as np, mujoco, sys
sys.path.insert(0, sys.argv[1] + "/tests")
from monitor import Plan, Scene
from monitor.certify import extrusion_swept as XS
from monitor.tolerances import DEFAULT
import test_redteam_9 as T
scene, plan = T._ball_plan([0.0, 0.5, 1.0], [0.6, 0.8, 0.7])
best = []
for r in range(7):
    t = time.perf_counter()
    for _ in range(5000):
        T._plan_pair(scene, plan, (0.0, 1.0), 0.0)
    best.append((time.perf_counter() - t) / 5000 * 1e6)
print(sys.argv[1], "median us", sorted(best)[3], "min", min(best), T._plan_pair(scene, plan, (0.0, 1.0), 0.0).verdict)
