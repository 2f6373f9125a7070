"""Per-call A/B of monitor.certify on the calls a tunnel Gate.step makes (recorded, then replayed).

PYTHONPATH=<this tree> python docs/notes/issue-12-tunnel-3/calls.py [rounds] [switch...]
Records the (scene, plan, request) of every certify call of 300 bench tunnel_gate steps, then
replays them (each plan's motion pack is cached after its first call: this times the engine after
the pack) with the switches off / on, interleaved; per-call medians over rounds of per-call means,
split by the certificate's verdict. Switches as in ab_inproc.py.
"""
import sys
import time

import mujoco
import numpy as np

from monitor.certify import engine as gate_mod
from monitor.certify import engine, ongoing  # noqa: F811
from monitor.gate import Gate

rounds = int(sys.argv[1]) if len(sys.argv) > 1 else 5
switches = sys.argv[2:] or ["direct", "start"]
calls = []
real = gate_mod.certify


def rec(scene, plan, **kw):
    calls.append((scene, plan, kw))
    return real(scene, plan, **kw)


gate_mod.certify = rec
m = mujoco.MjModel.from_xml_path("models/tunnel/scene.xml")
gate = Gate(m, margin=0.001)
d = mujoco.MjData(m)
mujoco.mj_resetDataKeyframe(m, d, 0)
for k in range(300):
    target = 0.3 if (k // 100) % 2 == 0 else -0.3
    gate.step(d, np.clip([12.0 * (target - d.qpos[0])], -6.0, 6.0), nstep=1)
gate_mod.certify = real
kind = [str(c.verdict) + ("+ext" if "extrusion" in c.stats["checker_mix"] else "") for c in (real(s, p, **kw) for s, p, kw in calls)]


def use(on):
    if "direct" in switches:
        engine._EXTRUSION_DIRECT = on
    if "start" in switches:
        ongoing._START_BOUND = on


def run():
    out = []
    for s, p, kw in calls:
        t = time.perf_counter()
        real(s, p, **kw)
        out.append(time.perf_counter() - t)
    return np.array(out)


res = {"old": [], "new": []}
for _ in range(rounds):
    for name, on in (("old", False), ("new", True)):
        use(on)
        res[name].append(run())
kinds = np.array(kind)
for v in sorted(set(kind)):
    sel = kinds == v
    o = np.median([r[sel].mean() for r in res["old"]]) * 1e6
    n = np.median([r[sel].mean() for r in res["new"]]) * 1e6
    print(f"{v:10s} {sel.sum():4d} calls: old {o:6.1f} us  new {n:6.1f} us  old/new {o / n:.3f}")
