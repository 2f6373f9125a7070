"""In-situ cost of the witness confirmation per violation certify call, old (shape_distance per candidate) vs new.

PYTHONPATH=<this tree> python docs/notes/issue-12-tunnel-4/confirm_split.py [rounds]
The bench's tunnel_gate workload (600 steps per run), engine._CONFIRM_COMPILED off / on alternating;
perf_counter timers around engine._find_witness, engine._confirm, the compiled kernel, shape_distance and
the witness-point helpers; medians over rounds of the total / 288 (the violation windows of a run), us.
"""
import sys, time, numpy as np, mujoco
from monitor.certify import engine as E
from monitor.certify import witness_kernels as WK
from monitor.geometry import distance as GD
from monitor.gate import Gate
m = mujoco.MjModel.from_xml_path("models/tunnel/scene.xml")
pc = time.perf_counter
acc = {}
def wrap(owner, name, key):
    f = getattr(owner, name)
    def w(*a, **k):
        t = pc()
        try: return f(*a, **k)
        finally:
            acc[key] = acc.get(key, 0.0) + pc() - t
    setattr(owner, name, w)
wrap(WK, "confirm_kernel", "kernel")
wrap(GD, "_solid_points", "solid_points"); wrap(GD, "_midpoint", "midpoint")
wrap(E, "_confirm", "confirm")
wrap(E, "_find_witness", "find_witness")
sd = GD.shape_distance
def sdw(*a, **k):
    t = pc()
    try: return sd(*a, **k)
    finally: acc["shape_distance"] = acc.get("shape_distance", 0.0) + pc() - t
import monitor.geometry.distance
monitor.geometry.distance.shape_distance = sdw
def run(steps=600):
    gate = Gate(m, margin=0.001); d = mujoco.MjData(m); mujoco.mj_resetDataKeyframe(m, d, 0)
    for k in range(steps):
        target = 0.3 if (k // 100) % 2 == 0 else -0.3
        gate.step(d, np.clip([12.0 * (target - d.qpos[0])], -6.0, 6.0), nstep=1)
res = {}
for r in range(int(sys.argv[1])):
    for on in (False, True):
        E._CONFIRM_COMPILED = on
        acc.clear(); run()
        for k, v in acc.items():
            res.setdefault((on, k), []).append(v / 288 * 1e6)
for (on, k), v in sorted(res.items()):
    print(on, k, round(float(np.median(v)), 1), "us per violation call")
