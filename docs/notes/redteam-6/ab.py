"""Thread time per gated tunnel step (bench-like controller: target switches every 100 windows; ball rests on the wall)."""
import sys, time, statistics, mujoco, numpy as np, warnings
warnings.simplefilter("ignore")
import logging; logging.disable(logging.WARNING)
from monitor._paths import scene_path
from monitor.gate import Gate
def run(steps):
    m = mujoco.MjModel.from_xml_path(str(scene_path("tunnel"))); d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, 0); g = Gate(m, margin=0.001)
    for k in range(30): g.step(d, np.zeros(1))  # warm
    t0 = time.thread_time()
    for k in range(steps):
        target = 0.3 if (k // 100) % 2 == 0 else -0.3
        g.step(d, np.clip([12.0 * (target - d.qpos[0])], -6, 6))
    return (time.thread_time() - t0) / steps * 1e6, g.stats["static_reused"]
res = [run(int(sys.argv[1])) for _ in range(3)]
print(statistics.median(r[0] for r in res), res[0][1])
