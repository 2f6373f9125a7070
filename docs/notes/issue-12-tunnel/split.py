"""Per-step time of Gate(tunnel).step and of extrusion.check_pairs / engine._run_extrusion / certify inside it.

usage: PYTHONPATH=<tree> python split.py (3 x 100 steps after 5 warm-up steps; us per step)."""
import collections, time, sys
import numpy as np, mujoco
from monitor.gate import Gate
from monitor.certify import extrusion, engine
acc = collections.Counter()
def wrap(mod, name):
    f = getattr(mod, name)
    def g(*a, **k):
        t = time.perf_counter(); r = f(*a, **k); acc[name] += time.perf_counter() - t; return r
    setattr(mod, name, g)
wrap(extrusion, "check_pairs"); wrap(engine, "_run_extrusion"); wrap(engine, "certify")
m = mujoco.MjModel.from_xml_path("/work/main/models/tunnel/scene.xml")
gate = Gate(m, margin=0.001); d = mujoco.MjData(m)
def run(n):
    mujoco.mj_resetDataKeyframe(m, d, 0); gate.reset()
    t = time.perf_counter()
    for k in range(n):
        target = 0.3 if (k // 25) % 2 == 0 else -0.3
        gate.step(d, np.clip([12.0 * (target - d.qpos[0])], -6, 6), nstep=1)
    return (time.perf_counter() - t) / n * 1e6
run(5); acc.clear()
tot = sum(run(100) for _ in range(3)) / 3
print(f"step {tot:.0f} us; " + ", ".join(f"{k} {v/300*1e6:.0f} us" for k, v in acc.items()))
