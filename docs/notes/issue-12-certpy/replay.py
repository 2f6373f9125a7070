"""Replay the certify calls of 300 tunnel gate steps; per kind, the median over rounds of the mean thread CPU per call (us).

PYTHONPATH=<tree> python replay.py [rounds]. The calls repeat (same plan and request): the call memo hits, so this times
the window path after the validation and the pack."""
import os
import sys
import time

import mujoco
import numpy as np

from monitor.certify import engine
from monitor.gate import Gate

rounds = int(sys.argv[1]) if len(sys.argv) > 1 else 7
tree = os.environ["PYTHONPATH"].split(":")[0]
calls = []
real = engine.certify
def rec(scene, plan, **kw):
    calls.append((scene, plan, kw))
    return real(scene, plan, **kw)
engine.certify = rec
engine._OWN_CERTIFY = rec
m = mujoco.MjModel.from_xml_path(os.path.join(tree, "models/tunnel/scene.xml"))
gate = Gate(m, margin=0.001)
d = mujoco.MjData(m)
mujoco.mj_resetDataKeyframe(m, d, 0)
for k in range(300):
    target = 0.3 if (k // 100) % 2 == 0 else -0.3
    gate.step(d, np.clip([12.0 * (target - d.qpos[0])], -6.0, 6.0), nstep=1)
engine.certify = real
engine._OWN_CERTIFY = real
kind = np.array([str(c.verdict) + ("+ext" if "extrusion" in c.stats["checker_mix"] else "") for c in (real(s, p, **kw) for s, p, kw in calls)])
res = []
for _ in range(rounds):
    out = []
    for s, p, kw in calls:
        t = time.thread_time_ns()
        real(s, p, **kw)
        out.append((time.thread_time_ns() - t) * 1e-9)
    res.append(np.array(out))
tag = os.path.basename(tree.rstrip("/"))
for v in sorted(set(kind)):
    sel = kind == v
    print(f"REPLAY {tag:8s} {v:16s} {sel.sum():4d} calls: {np.median([r[sel].mean() for r in res]) * 1e6:7.1f} us")
