"""In-process A/B of this branch's switches on the tunnel gate; certificates compared in full.

PYTHONPATH=<this tree> python docs/notes/issue-12-tunnel-4/ab_inproc.py [rounds] [steps] [switch...]
switch: "confirm" (engine._CONFIRM_COMPILED: the compiled witness confirmation), "segments"
(engine._LAZY_SEGMENTS: a Plan's translation segments built in the compiled pass); default both. "old" = off, "new" = on,
rounds interleaved (old, new, new, old, ...). Workload: the bench's tunnel_gate (Gate(margin=0.001),
target +-0.3 m switching every 100 windows, one 10 ms step per window). Every step's certificate
(to_dict without wall_seconds, pairs included) and the final state must be identical between the
two. Prints medians of per-round means of the step, wall (perf_counter) and thread CPU time (us), and
the thread CPU time of engine.certify inside the steps (us per step).
"""
import hashlib
import sys
import time

import mujoco
import numpy as np

from monitor.certify import engine
from monitor.gate import Gate

rounds = int(sys.argv[1]) if len(sys.argv) > 1 else 6
steps = int(sys.argv[2]) if len(sys.argv) > 2 else 600
switches = sys.argv[3:] or ["confirm", "segments"]
SW = {"confirm": (engine, "_CONFIRM_COMPILED"), "segments": (engine, "_LAZY_SEGMENTS")}
m = mujoco.MjModel.from_xml_path("models/tunnel/scene.xml")
real = engine.certify
cert_cpu = [0.0]
kinds: dict = {}   # certificate kind -> [cpu seconds, calls] of the current run


def timed(*a, **k):
    t = time.thread_time()
    c = real(*a, **k)
    dt = time.thread_time() - t
    cert_cpu[0] += dt
    kind = str(c.verdict) + ("+extrusion" if "extrusion" in c.stats.get("checker_mix", {}) else "")
    acc = kinds.setdefault(kind, [0.0, 0])
    acc[0] += dt
    acc[1] += 1
    return c


engine.certify = timed   # Gate._certify imports it from the engine at call time


def use(on):
    for s in switches:
        mod, name = SW[s]
        assert hasattr(mod, name), name
        setattr(mod, name, on)


def run():
    gate = Gate(m, margin=0.001)
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, 0)
    h = hashlib.md5()
    wall = cpu = 0.0
    cert_cpu[0] = 0.0
    kinds.clear()
    for k in range(steps):
        target = 0.3 if (k // 100) % 2 == 0 else -0.3
        c = np.clip([12.0 * (target - d.qpos[0])], -6.0, 6.0)
        t, u = time.perf_counter(), time.thread_time()
        r = gate.step(d, c, nstep=1)
        wall += time.perf_counter() - t
        cpu += time.thread_time() - u
        cd = r.certificate.to_dict()
        cd["stats"].pop("wall_seconds")
        h.update(repr((r.verdict, cd)).encode())
    h.update(d.qpos.tobytes() + d.qvel.tobytes())
    return wall / steps, cpu / steps, h.hexdigest(), cert_cpu[0] / steps, {k: v[0] / v[1] for k, v in kinds.items()}


res = {False: [], True: []}
use(True)
run()          # warm both
use(False)
run()
for r in range(rounds):
    for on in ((False, True) if r % 2 == 0 else (True, False)):
        use(on)
        res[on].append(run())
digests = {x[2] for v in res.values() for x in v}
assert len(digests) == 1, "certificates differ between old and new"
for i, what in ((0, "wall"), (1, "cpu"), (3, "certify cpu")):
    o = np.median([x[i] for x in res[False]]) * 1e6
    n = np.median([x[i] for x in res[True]]) * 1e6
    print(f"{what}: old {o:6.1f} us  new {n:6.1f} us  old/new {o / n:.3f}   ({switches}, {rounds} rounds x {steps})")
for kind in sorted(res[False][0][4]):
    o = np.median([x[4][kind] for x in res[False]]) * 1e6
    n = np.median([x[4][kind] for x in res[True]]) * 1e6
    print(f"certify cpu per call, {kind}: old {o:6.1f} us  new {n:6.1f} us  old/new {o / n:.3f}")
print("certificates identical:", digests.pop())
