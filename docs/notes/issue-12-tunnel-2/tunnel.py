import time, cProfile, pstats, sys, collections
import numpy as np, mujoco
from monitor.gate import Gate
from monitor._paths import scene_path
m = mujoco.MjModel.from_xml_path("/work/main/models/tunnel/scene.xml")
gate = Gate(m, margin=0.001)
d = mujoco.MjData(m)
def run(n):
    mujoco.mj_resetDataKeyframe(m, d, 0); gate.reset()
    vs = collections.Counter(); meth = collections.Counter()
    t = time.perf_counter()
    for k in range(n):
        target = 0.3 if (k // 25) % 2 == 0 else -0.3
        r = gate.step(d, np.clip([12.0 * (target - d.qpos[0])], -6, 6), nstep=1)
        vs[str(r.verdict)] += 1
    return (time.perf_counter() - t) / n, vs
run(5)
dt, vs = run(100); print("per step us", dt * 1e6, vs)
pr = cProfile.Profile(); pr.enable(); run(100); pr.disable()
pstats.Stats(pr).sort_stats(sys.argv[1] if len(sys.argv) > 1 else "cumulative").print_stats(45)
