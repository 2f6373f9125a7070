"""Inclusive plain-timer split of monitor.certify inside a tunnel Gate.step, per certificate verdict.

PYTHONPATH=<tree> python docs/notes/issue-12-tunnel-4/split.py [steps] [rounds]
Runs the bench's tunnel_gate controller (tunnel-3's dump.py) for `steps` steps per round with
timers (time.perf_counter) wrapped around certify and the functions below it; prints per-call
medians over rounds of the per-call mean (µs), split by certified-with-extrusion /
violation / culled. Inclusive times: a part includes the parts it calls.
"""
import sys
import time
from collections import defaultdict

import mujoco
import numpy as np

import monitor.certify.engine as E
import monitor.certify.extrusion_swept as XS
import monitor.geometry.distance as D
from monitor.gate import Gate
from monitor.motion.plan import Plan

steps = int(sys.argv[1]) if len(sys.argv) > 1 else 600
rounds = int(sys.argv[2]) if len(sys.argv) > 2 else 3
pc = time.perf_counter
cur = defaultdict(float)


def wrap(owner, name, key):
    f = getattr(owner, name)

    def w(*a, **k):
        t = pc()
        try:
            return f(*a, **k)
        finally:
            cur[key] += pc() - t
    setattr(owner, name, w)


for n in ("_fast_inputs", "_fast_prep", "_certify_fast", "_extrusion_decided", "_run_extrusion",
          "extrusion_stats", "_checked_result", "_find_witness", "_window_certificate", "_translates",
          "deepen", "_window_kernel"):
    if hasattr(E, n):
        wrap(E, n, n)
wrap(XS, "decide_pair", "decide_pair")
wrap(D, "shape_distance", "shape_distance")
wrap(Plan, "body_poses", "body_poses")
wrap(Plan, "translation_segments", "translation_segments")
wrap(XS, "decide_plan_pair", "decide_plan_pair") if hasattr(XS, "decide_plan_pair") else None
real = E.certify
per_kind = defaultdict(lambda: defaultdict(list))   # kind -> key -> [per-round mean]


def certify(*a, **k):
    cur.clear()
    t = pc()
    c = real(*a, **k)
    cur["certify"] = pc() - t
    kind = str(c.verdict) + ("+ext" if "extrusion" in c.stats["checker_mix"] else "")
    acc[kind].append(dict(cur))
    return c


E.certify = certify   # Gate._certify imports it from the engine at call time
m = mujoco.MjModel.from_xml_path("models/tunnel/scene.xml")
for r in range(rounds + 1):
    acc = defaultdict(list)
    gate = Gate(m, margin=0.001)
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, 0)
    t = pc()
    for k in range(steps):
        target = 0.3 if (k // 100) % 2 == 0 else -0.3
        gate.step(d, np.clip([12.0 * (target - d.qpos[0])], -6.0, 6.0), nstep=1)
    wall = (pc() - t) / steps
    if r == 0:
        continue   # warm-up round
    per_kind["_step"]["step"].append(wall)
    for kind, rows in acc.items():
        keys = set().union(*rows)
        per_kind[kind]["_calls"].append(len(rows))
        for key in keys:
            per_kind[kind][key].append(sum(x.get(key, 0.0) for x in rows) / len(rows))
print(f"step median {np.median(per_kind['_step']['step']) * 1e6:.0f} us (timers on)")
for kind, d_ in per_kind.items():
    if kind == "_step":
        continue
    print(f"{kind}: {int(np.median(d_['_calls']))} calls/round")
    for key in sorted((k for k in d_ if k != "_calls"), key=lambda k: -np.median(d_[k])):
        print(f"   {key:22s} {np.median(d_[key]) * 1e6:7.1f} us")
