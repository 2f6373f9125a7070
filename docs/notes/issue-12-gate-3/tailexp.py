"""Experiment: braking tail by the mj_step loop vs mujoco's C rollout (bit identity, cost).

PYTHONPATH=$PWD python docs/notes/issue-12-gate-3/tailexp.py Pusher-v5 60
"""
import sys, time
import numpy as np, gymnasium as gym, mujoco
from mujoco import _rollout
import monitor.envs  # noqa
from monitor.gym_gate import SafetyGate
from monitor.gate import hold_ctrl

env_id = sys.argv[1]; N = int(sys.argv[2])
kw = {"pairs": "mujoco"} if "Pusher" in env_id else {}
g = SafetyGate(gym.make(env_id), **kw)
gate = g.gate; m = gate.model
ro = gate._rollout
states = []
g.reset(seed=0)
rng = np.random.default_rng(0)
for k in range(N):
    a = g.action_space.sample()
    d = g.unwrapped.data
    states.append((np.array(d.qpos), np.array(d.qvel), np.array(d.act), d.time, np.array(a, dtype=np.float64),
                   np.array(d.qacc_warmstart), np.array(d.ctrl)))
    _, _, te, tr, _ = g.step(a)
    if te or tr: g.reset(seed=0)
d = mujoco.MjData(m)
FULL = int(mujoco.mjtState.mjSTATE_FULLPHYSICS); USER = int(mujoco.mjtState.mjSTATE_USER)
nfull = mujoco.mj_stateSize(m, FULL); nuser = mujoco.mj_stateSize(m, USER)
R = _rollout.Rollout(nthread=0)
tail_d = mujoco.MjData(m)
ns = gate.brake_steps; nstep = gate.frame_skip
lens = []; t_loop = []; t_ro = []; same = 0
INT = mujoco.mjtState.mjSTATE_INTEGRATION
end = np.empty(mujoco.mj_stateSize(m, INT))
out = np.empty((1, ns, nfull)); ctl = np.empty((1, ns, nuser)); s0 = np.empty((1, nfull)); w0 = np.empty((1, m.nv))
for qpos, qvel, act, t, a, warm, c in states:
    mujoco.mj_resetData(m, d); d.qpos[:] = qpos; d.qvel[:] = qvel; d.act[:] = act; d.time = t; d.qacc_warmstart[:] = warm
    d.ctrl[:] = c
    # loop (today's)
    ro.states(d, a, nstep)
    t1 = time.perf_counter()
    rows, brake = ro.brake_rows(d, a, nstep, lambda dd: hold_ctrl(m, dd), ns, gate.brake_vel_tol)
    t2 = time.perf_counter()
    # rollout: from the scratch's window end
    mujoco.mj_getState(m, ro.scratch, end, INT)
    mujoco.mj_setState(m, tail_d, end, INT)
    t3 = time.perf_counter()
    tail_d.ctrl[:] = brake
    mujoco.mj_getState(m, tail_d, s0[0], FULL)
    mujoco.mj_getState(m, tail_d, ctl[0, 0], USER); ctl[0, 1:] = ctl[0, 0]
    w0[0] = tail_d.qacc_warmstart
    R.rollout([m], [tail_d], ns, USER, s0, w0, ctl, out, None, None)
    w = out[0, :, 1 + m.nq:1 + m.nq + m.nv]
    ok = np.abs(w).max(axis=1) <= gate.brake_vel_tol
    e = int(ok.argmax()) + 1 if ok.any() else ns
    t4 = time.perf_counter()
    r2 = np.concatenate((s0[:, :1 + m.nq + m.nv], out[0, :e, :1 + m.nq + m.nv]))
    same += np.array_equal(r2, rows)
    lens.append(len(rows) - 1); t_loop.append(t2 - t1); t_ro.append(t4 - t3)
print(env_id, "tail substeps median", np.median(lens), "min", min(lens), "max", max(lens), "identical", same, "/", len(states))
print("loop (tail only) median us", np.median(t_loop) * 1e6, "rollout (tail only) median us", np.median(t_ro) * 1e6)
