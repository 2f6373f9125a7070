
import json, sys, time
launched = float(sys.argv[1])
t0 = time.time()
import numpy as np
import mujoco
import monitor
from monitor._paths import scene_path
t_import = time.time() - t0
model = mujoco.MjModel.from_xml_path(str(scene_path("arm")))
scene = monitor.Scene.from_model(model)
q0 = model.qpos0.copy()
q1 = q0.copy(); q1[0] += 0.05; q1[2] += 0.05
plan = monitor.Plan(np.array([0.0, 0.01]), np.stack([q0, q1]), model=model)
t = time.time()
cert = monitor.certify(scene, plan)
t_end = time.time()
later = []
for _ in range(3):
    t1 = time.perf_counter(); monitor.certify(scene, plan); later.append(time.perf_counter() - t1)
res = {"import_s": t_import, "first_call_s": t_end - t, "launch_to_answer_s": t_end - launched,
       "later_median_s": float(np.median(later)), "verdict": str(cert.verdict),
       "pairs": len(scene.candidate_pairs)}
print("START " + json.dumps(res))

