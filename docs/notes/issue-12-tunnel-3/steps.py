"""Per-step wall time of the bench's tunnel_gate workload and of its ungated mj_step loop, in one process.

PYTHONPATH=<tree> python docs/notes/issue-12-tunnel-3/steps.py [blocks]
blocks x 200 gated windows (target +-0.3 m switching every 100; one 10 ms step each) interleaved with
blocks x 2000 ungated windows (same controller, plain mj_step); prints the medians of the block means
(us) and their ratio, as monitor/bench/targets.py::plain_gate does.
"""
import sys
import time

import mujoco
import numpy as np

from monitor.gate import Gate

blocks = int(sys.argv[1]) if len(sys.argv) > 1 else 5
m = mujoco.MjModel.from_xml_path("models/tunnel/scene.xml")
gate = Gate(m, margin=0.001)
dg, du = mujoco.MjData(m), mujoco.MjData(m)


def ctrl(d, k):
    target = 0.3 if (k // 100) % 2 == 0 else -0.3
    return np.clip([12.0 * (target - d.qpos[0])], -6.0, 6.0)


def gated(n):
    mujoco.mj_resetDataKeyframe(m, dg, 0)
    gate.reset()
    tot = 0.0
    for k in range(n):
        c = ctrl(dg, k)
        t = time.perf_counter()
        gate.step(dg, c, nstep=1)
        tot += time.perf_counter() - t
    return tot / n


def ungated(n):
    mujoco.mj_resetDataKeyframe(m, du, 0)
    tot = 0.0
    for k in range(n):
        c = ctrl(du, k)
        t = time.perf_counter()
        du.ctrl[:] = c
        mujoco.mj_step(m, du)
        tot += time.perf_counter() - t
    return tot / n


gated(50)
g, u = [], []
for _ in range(blocks):
    g.append(gated(200))
    u.append(ungated(2000))
G, U = np.median(g) * 1e6, np.median(u) * 1e6
print(f"gated {G:.0f} us  ungated {U:.2f} us  ratio {G / U:.0f}x")
