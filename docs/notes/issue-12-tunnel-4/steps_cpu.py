"""Per-step thread CPU time of the bench's tunnel_gate workload and of monitor.certify inside it.

PYTHONPATH=<tree> python docs/notes/issue-12-tunnel-4/steps_cpu.py [blocks] [steps]
blocks x steps gated windows (target +-0.3 m switching every 100; one 10 ms step each), after one
warm-up block; prints the medians over blocks of the per-step mean of time.thread_time (this
thread's CPU time: less sensitive than wall time to the other processes on the shared cores) for
the whole Gate.step and for engine.certify within it (us), one line, for alternating A/B runs.
"""
import sys
import time

import mujoco
import numpy as np

from monitor.certify import engine
from monitor.gate import Gate

blocks = int(sys.argv[1]) if len(sys.argv) > 1 else 5
steps = int(sys.argv[2]) if len(sys.argv) > 2 else 600
m = mujoco.MjModel.from_xml_path("models/tunnel/scene.xml")
real = engine.certify
acc = [0.0]


def timed(*a, **k):
    t = time.thread_time()
    try:
        return real(*a, **k)
    finally:
        acc[0] += time.thread_time() - t


engine.certify = timed   # Gate._certify imports it from the engine at call time
tot, cer = [], []
for b in range(blocks + 1):
    gate = Gate(m, margin=0.001)
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, 0)
    acc[0] = 0.0
    t = time.thread_time()
    for k in range(steps):
        target = 0.3 if (k // 100) % 2 == 0 else -0.3
        gate.step(d, np.clip([12.0 * (target - d.qpos[0])], -6.0, 6.0), nstep=1)
    if b:
        tot.append((time.thread_time() - t) / steps * 1e6)
        cer.append(acc[0] / steps * 1e6)
print(f"step {np.median(tot):.1f} certify {np.median(cer):.1f}")
