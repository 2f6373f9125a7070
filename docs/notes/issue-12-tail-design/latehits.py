"""Corroborate profile.py's late hits: the Arm's brakes certified over 0.25 s that are a violation by 0.5 s.

PYTHONPATH=<tree> python docs/notes/issue-12-tail-design/latehits.py START [START ...]

START: indices into the starts of ``profile.py monitor/Arm-v0 30 1`` (its "late_violations").
Holds the brake 0.5 s from each and samples every substep (and 20 linear sub-samples between
substeps) the signed distance of the witness pair (finger_l, floor) by ``mj_geomDistance``: an
independent second opinion on the certify witness, not a certificate. Prints "LATE {...}".
"""
import json, sys

import mujoco
import numpy as np

import wl

W, starts = wl.brake_starts("monitor/Arm-v0", 30, 1)
m = W.model
ga = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, "finger_l")
gb = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, "floor")
d = mujoco.MjData(m)
fromto = np.zeros(6)
dt = m.opt.timestep
out = []
for j in map(int, sys.argv[1:]):
    state, brake, _, _ = starts[j]
    mujoco.mj_setState(m, d, state, mujoco.mjtState.mjSTATE_INTEGRATION)
    d.ctrl[:] = brake
    t0 = d.time
    q = [d.qpos.copy()]
    for _ in range(int(round(0.5 / dt))):
        mujoco.mj_step(m, d)
        q.append(d.qpos.copy())
    probe = mujoco.MjData(m)
    dist, times = [], []
    for k in range(len(q) - 1):
        for s in np.linspace(0.0, 1.0, 20, endpoint=False):
            probe.qpos[:] = q[k] + s * (q[k + 1] - q[k])
            mujoco.mj_kinematics(m, probe)
            dist.append(mujoco.mj_geomDistance(m, probe, ga, gb, 0.2, fromto))
            times.append((k + s) * dt)
    dist, times = np.array(dist), np.array(times)
    first = np.flatnonzero(dist < 0)
    out.append({"start": j, "min_distance_first_0.25s_m": float(dist[times <= 0.25].min()),
                "min_distance_0.25_0.5s_m": float(dist[times > 0.25].min()),
                "first_penetration_s_after_window_end": float(times[first[0]]) if len(first) else None})
print("LATE " + json.dumps(out))
