"""Tunnel Gate.step (the bench's tunnel_gate workload: same model, reset, controller, margin) timed per step
by thread CPU time and wall; R blocks of 200 steps. Prints the median over blocks of the per-block mean.
"""
import gc
import os
import sys
import time

import mujoco
import numpy as np

import monitor
from monitor.bench.targets import _scene_file
from monitor.gate import Gate

R = int(sys.argv[1]) if len(sys.argv) > 1 else 5
model = mujoco.MjModel.from_xml_path(str(_scene_file("tunnel")))
gate = Gate(model, margin=0.001)
d = mujoco.MjData(model)
def block(n=200):
    mujoco.mj_resetDataKeyframe(model, d, 0)
    gate.reset()
    cpu = wall = 0
    for k in range(n):
        target = 0.3 if (k // 100) % 2 == 0 else -0.3
        ctrl = np.clip([12.0 * (target - d.qpos[0])], -6.0, 6.0)
        c0, w0 = time.thread_time_ns(), time.perf_counter_ns()
        gate.step(d, ctrl, nstep=1)
        cpu += time.thread_time_ns() - c0
        wall += time.perf_counter_ns() - w0
    return cpu / n / 1e3, wall / n / 1e3
block(20)
gc.collect()
res = [block() for _ in range(R)]
tag = os.path.basename(os.path.dirname(os.path.dirname(monitor.__file__)))
print(f"CPU {tag} cpu_us {np.median([r[0] for r in res]):.1f} wall_us {np.median([r[1] for r in res]):.1f}")
