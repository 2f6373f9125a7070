import time, cProfile, pstats, sys
import numpy as np, mujoco
from monitor.gate import Gate
m = mujoco.MjModel.from_xml_path("models/hand30/scene.xml")
lo, hi = m.actuator_ctrlrange[:, 0], m.actuator_ctrlrange[:, 1]
targets = np.random.default_rng(0).uniform(lo, hi, size=(64, m.nu))
gate = Gate(m); d = mujoco.MjData(m)
def run(n):
    mujoco.mj_resetData(m, d); gate.reset(); t = time.perf_counter()
    for k in range(n):
        gate.step(d, targets[(k // 10) % 64], nstep=5)
    return (time.perf_counter() - t) / n
run(3); print("ms/step", 1e3 * run(20))
pr = cProfile.Profile(); pr.enable(); run(20); pr.disable()
pstats.Stats(pr).sort_stats(sys.argv[1] if len(sys.argv) > 1 else "cumulative").print_stats(40)
