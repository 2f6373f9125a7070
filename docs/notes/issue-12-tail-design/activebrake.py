"""Q3(e): a damping brake recomputed once per window (piecewise constant, like any action) vs the held hold.

PYTHONPATH=<tree> python docs/notes/issue-12-tail-design/activebrake.py WORK BLOCKS EVERY

Same starts as profile.py. From each window end, over 2 s, three kinds of brake:
* "hold": the gate's brake (hold_ctrl at the window's end) held: the motion the gate certifies;
* "damp c": every frame_skip substeps (one env step) the control is recomputed from the state:
  position servos (affine bias, bias1 = -kp) target hold - c * qvel (the hold's target, i.e. the
  window end's position, plus a damping term: force kp (q_hold - q) - kp c v0),
  motors (no bias) -c * qvel / (gain * gear) (Pusher: torque -c v0), velocity servos 0; clipped
  to ctrlrange. c in s for servos, N m s / rad for motors. Held for the window, as an action is.
Reports per kind: how many starts reach max|qvel| <= brake_vel_tol (1e-3) within 2 s, the time
(median, p90), and the brake motion up to that time (or 2 s) certified with the gate's scene and
request (count certified / violation). Prints "ACTIVE {...}".
"""
import json, sys

import mujoco
import numpy as np

import wl
from monitor.certify.engine import certify
from monitor.motion.plan import Plan

work, blocks, every = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
W, starts = wl.brake_starts(work, blocks, every)
g, m = W.gate, W.model
fs = {"Pusher-v5": 5, "monitor/Arm-v0": 10, "hand30": 5, "tunnel": 1}[work]

dt = m.opt.timestep
N = int(round(2.0 / dt))
tol = g.brake_vel_tol
pos = (m.actuator_biastype == int(mujoco.mjtBias.mjBIAS_AFFINE)) & (m.actuator_biasprm[:, 1] < 0)
motor = m.actuator_biastype == int(mujoco.mjtBias.mjBIAS_NONE)
jnt = m.actuator_trnid[:, 0]
qadr, vadr = m.jnt_qposadr[jnt], m.jnt_dofadr[jnt]
gain, gear = m.actuator_gainprm[:, 0], m.actuator_gear[:, 0]
lo, hi = m.actuator_ctrlrange[:, 0], m.actuator_ctrlrange[:, 1]
limited = m.actuator_ctrllimited.astype(bool)
cs = {"Pusher-v5": (0.5, 1.0, 2.0), "monitor/Arm-v0": (0.02, 0.05, 0.1), "hand30": (0.02, 0.05, 0.1),
      "tunnel": (0.0,)}[work]

def law(d, c, hold):
    u = hold.copy()
    u[pos] = (hold - c * d.qvel[vadr] * gear)[pos]  # the hold target stays anchored (gravity sag)
    u[motor] = (-c * d.qvel[vadr] / (gain * gear))[motor]
    return np.where(limited, np.clip(u, lo, hi), u)

d = mujoco.MjData(m)
scene, req = g.scene, g.request
res = {}
for kind in ["hold"] + [f"damp {c}" for c in cs]:
    times, verdicts = [], []
    for state, hold, mp, mq in starts:
        mujoco.mj_setState(m, d, state, mujoco.mjtState.mjSTATE_INTEGRATION)
        t = np.empty(N + 1); q = np.empty((N + 1, m.nq))
        t[0], q[0] = d.time, d.qpos
        end = None
        for k in range(1, N + 1):
            if (k - 1) % fs == 0:
                d.ctrl[:] = hold if kind == "hold" else law(d, float(kind.split()[1]), hold)
            mujoco.mj_step(m, d)
            t[k], q[k] = d.time, d.qpos
            if np.abs(d.qvel).max() <= tol:
                end = k
                break
        k = end if end is not None else N
        times.append(None if end is None else k * dt)
        p = Plan._trusted(t[:k + 1].copy(), q[:k + 1].copy(), model=m, mocap_pos=mp.copy(), mocap_quat=mq.copy())
        verdicts.append(str(certify(scene, p, request=req).verdict))
    ok = [x for x in times if x is not None]
    res[kind] = {"rest_within_2s": len(ok), "t_rest_median": float(np.median(ok)) if ok else None,
                 "t_rest_p90": float(np.percentile(ok, 90)) if ok else None,
                 "certified": verdicts.count("certified"), "violation": verdicts.count("violation"),
                 "uncertain": verdicts.count("uncertain")}
print("ACTIVE " + json.dumps({"work": work, "starts": len(starts), "frame_skip": fs, "kinds": res}))
