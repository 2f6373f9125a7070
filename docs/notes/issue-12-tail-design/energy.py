"""Q3(e): is the brake's energy non-increasing along the simulated tail (the premise of an energy stop bound)?

PYTHONPATH=<tree> python docs/notes/issue-12-tail-design/energy.py WORK BLOCKS EVERY

Same starts as profile.py (every EVERY-th braking tail of the gated workload at the defaults).
From each, holds the brake for 1 s and evaluates per substep
  V = kinetic + gravity potential (MuJoCo's mjENBL_ENERGY: d.energy) + the position servos'
      potential sum_a 1/2 kp_a (gear_a q_a - ctrl_a)^2 (affine-bias actuators with bias1 = -kp;
      motors and velocity servos store none),
and reports how many substeps increase V by more than 1e-9 relative, the largest relative
increase, and V at 0.25 s over V at 0 (median). A non-increasing V gives, for every later time,
sum_a 1/2 kp_a (q_a - c_a)^2 <= V(H) - min(gravity potential + kinetic) over the reachable set:
a bound on the motion left after a tail of H s that needs no further integration.
Prints "ENERGY {...}".
"""
import json, sys

import mujoco
import numpy as np

import wl

work, blocks, every = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
W, starts = wl.brake_starts(work, blocks, every)
g, m = W.gate, W.model

m.opt.enableflags |= int(mujoco.mjtEnableBit.mjENBL_ENERGY)   # a copy's flag would do; the run is over
servo = (m.actuator_biastype == int(mujoco.mjtBias.mjBIAS_AFFINE)) & (m.actuator_trntype == int(mujoco.mjtTrn.mjTRN_JOINT))
kp = np.where(servo, -m.actuator_biasprm[:, 1], 0.0)
adr = m.jnt_qposadr[m.actuator_trnid[:, 0]]
gear = m.actuator_gear[:, 0]
d = mujoco.MjData(m)
N = int(round(1.0 / m.opt.timestep))
kH = int(round(0.25 / m.opt.timestep))
ups, worst, ratio = 0, 0.0, []
total = 0
for state, brake, _, _ in starts:
    mujoco.mj_setState(m, d, state, mujoco.mjtState.mjSTATE_INTEGRATION)
    d.ctrl[:] = brake
    V = np.empty(N + 1)
    for k in range(N + 1):
        if k:
            mujoco.mj_step(m, d)
        mujoco.mj_forward(m, d)   # energy of the current state (mj_step's is the pre-step state's)
        servo_pot = 0.5 * float(np.sum(kp * (gear * d.qpos[adr] - d.ctrl) ** 2))
        V[k] = d.energy[0] + d.energy[1] + servo_pot
    dv = np.diff(V)
    scale = np.maximum(np.abs(V[:-1]), 1e-12)
    inc = dv / scale
    ups += int((inc > 1e-9).sum())
    total += N
    worst = max(worst, float(inc.max()))
    ratio.append((V[kH] - V[-1]) / max(V[0] - V[-1], 1e-300))
print("ENERGY " + json.dumps({"work": work, "starts": len(starts), "servo_actuators": int(servo.sum()),
                             "nu": int(m.nu), "substeps": total, "substeps_V_increases": ups,
                             "largest_relative_increase": worst,
                             "share_of_energy_drop_left_after_0.25s_median": float(np.median(ratio))}))
