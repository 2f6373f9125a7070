"""Tunnel gate run (the loop of /work/wt/prof/tunnel.py): every first-contact query, new vs former.

Wraps ``extrusion.quadratic_first_time`` to record each call, then replays the call with the
former bisection (``quadratic_first_time_bisection``) and compares times and solve counts.
Also times the ungated ``mj_step`` loop in the same process.
Run: PYTHONPATH=$PWD /work/main/.venv/bin/python docs/notes/issue-12-extrusion-speed/tunnel_first_times.py
"""
import collections
import time

import mujoco
import numpy as np

from monitor.certify import extrusion
from monitor.certify.extrusion_null import quadratic_first_time, quadratic_first_time_bisection
from monitor.gate import Gate

calls = []


def spy(a, b, r, tl, th, level, tol):
    t0 = time.perf_counter()
    out = quadratic_first_time(a, b, r, tl, th, level, tol)
    calls.append((a, b, r, tl, th, level, tol, out, time.perf_counter() - t0))
    return out


extrusion.quadratic_first_time = spy
m = mujoco.MjModel.from_xml_path("/work/main/models/tunnel/scene.xml")
gate = Gate(m, margin=0.001)
d = mujoco.MjData(m)


def run(n):
    mujoco.mj_resetDataKeyframe(m, d, 0)
    gate.reset()
    vs = collections.Counter()
    t = time.perf_counter()
    for k in range(n):
        target = 0.3 if (k // 25) % 2 == 0 else -0.3
        r = gate.step(d, np.clip([12.0 * (target - d.qpos[0])], -6, 6), nstep=1)
        vs[str(r.verdict)] += 1
    return (time.perf_counter() - t) / n, vs


run(5)
calls.clear()
dt, vs = run(100)
mujoco.mj_resetDataKeyframe(m, d, 0)
t = time.perf_counter()
for _ in range(2000):
    mujoco.mj_step(m, d)
dt0 = (time.perf_counter() - t) / 2000
print(f"gated step {dt * 1e6:.0f} us, ungated mj_step {dt0 * 1e6:.2f} us, ratio {dt / dt0:.0f}x, {dict(vs)}")
dts, n_new, n_old, t_new, t_old = [], [], [], [], []
for a, b, r, tl, th, level, tol, (tau, _, n), sec in calls:
    t1 = time.perf_counter()
    tau0, _, n0 = quadratic_first_time_bisection(a, b, r, tl, th, level, tol)
    t_old.append(time.perf_counter() - t1)
    t_new.append(sec)
    dts.append(tau - tau0)
    n_new.append(n)
    n_old.append(n0)
print(f"{len(calls)} first-contact queries: max |tau_new - tau_old| = {np.abs(dts).max():.3g} s; "
      f"solves median new {np.median(n_new):.0f} (max {max(n_new)}) vs former {np.median(n_old):.0f}; "
      f"time median new {np.median(t_new) * 1e6:.0f} us vs former {np.median(t_old) * 1e6:.0f} us "
      f"(ratio {np.median(t_old) / np.median(t_new):.0f}x)")
