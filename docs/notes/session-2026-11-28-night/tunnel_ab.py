import time, sys, numpy as np, mujoco
import monitor
from monitor._paths import scene_path
model = mujoco.MjModel.from_xml_path(str(scene_path("tunnel")))
gate = monitor.Gate(model, margin=0.001)
d = mujoco.MjData(model)
def run(n):
    mujoco.mj_resetDataKeyframe(model, d, 0); gate.reset()
    t = time.thread_time()
    for k in range(n):
        target = 0.3 if (k // 25) % 2 == 0 else -0.3
        gate.step(d, np.clip([12.0 * (target - d.qpos[0])], -6.0, 6.0), nstep=1)
    return (time.thread_time() - t) / n
run(50)
print("%.1f" % (1e6 * np.median([run(100) for _ in range(7)])))
