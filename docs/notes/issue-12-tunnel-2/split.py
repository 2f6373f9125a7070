"""Unprofiled split of a tunnel Gate.step: wall time inside selected functions (timing wrappers).

PYTHONPATH=<tree> python docs/notes/issue-12-tunnel-2/split.py
"""
import collections
import time

import mujoco
import numpy as np

from monitor.certify import engine, ongoing
from monitor.gate import Gate
from monitor.motion import plan as plan_mod

acc = collections.Counter()
cnt = collections.Counter()


def wrap(mod, name, label=None):
    f = getattr(mod, name)
    label = label or name

    def w(*a, **k):
        t = time.perf_counter()
        try:
            return f(*a, **k)
        finally:
            acc[label] += time.perf_counter() - t
            cnt[label] += 1
    setattr(mod, name, w)


for n in ("certify", "_fast_inputs", "_certify_fast", "_python_stages", "_run_extrusion", "_find_witness",
          "_window_kernel", "extrusion_stats", "_plan_inputs"):
    wrap(engine, n)
wrap(engine, "deepen")
from monitor.certify import kernels as KSm
from monitor.motion import pack as packm
from monitor.motion import _kinematics as Km
wrap(KSm, "trajectory_pack_memo")
wrap(KSm, "_pack_agrees")
wrap(packm, "pack_trajectory")
wrap(packm, "plan_data_agrees")
wrap(Km, "check_times_in_window")
P = plan_mod.Plan
for n in ("translation_segments", "body_poses", "_fk", "_qpos_many", "_setup", "_trusted"):
    f = getattr(P, n)

    def mk(f, n):
        def w(self, *a, **k):
            t = time.perf_counter()
            try:
                return f(self, *a, **k)
            finally:
                acc["Plan." + n] += time.perf_counter() - t
                cnt["Plan." + n] += 1
        return w
    setattr(P, n, mk(f, n))

m = mujoco.MjModel.from_xml_path("/work/main/models/tunnel/scene.xml")
gate = Gate(m, margin=0.001)
d = mujoco.MjData(m)


def run(n):
    mujoco.mj_resetDataKeyframe(m, d, 0)
    gate.reset()
    t = time.perf_counter()
    for k in range(n):
        target = 0.3 if (k // 25) % 2 == 0 else -0.3
        gate.step(d, np.clip([12.0 * (target - d.qpos[0])], -6, 6), nstep=1)
    return time.perf_counter() - t


run(20)
tot = collections.Counter()
reps = 5
for _ in range(reps):
    acc.clear()
    cnt.clear()
    tot["step"] += run(100)
    for k, v in acc.items():
        tot[k] += v
print(f"per step (us), {reps}x100 steps, includes wrapper overhead")
for k, v in sorted(tot.items(), key=lambda kv: -kv[1]):
    print(f"{k:28s} {v / reps / 100 * 1e6:8.1f}  calls/step {cnt[k] / 100 if k in cnt else 1:.2f}")
