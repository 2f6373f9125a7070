"""Prototype (a) against ``monitor.gate.Rollout``: window and braking-tail rows compared byte for byte.

Usage: PYTHONPATH=$PWD python docs/notes/issue-12-wholestep/bitcheck.py [tunnel_steps] [pusher_steps]

Drives the real gate (tunnel: the bench's controller, ``Gate.step``; Pusher: ``SafetyGate`` with
seeded ``action_space.sample()``), and before every step computes the step's rows twice from the
live data: with an independent ``Rollout`` (``_window``, then ``brake_rows(..., window_fresh=True)``
with ``hold_ctrl``, the gate's own sequence), with ``cmj.Physics.run`` (one compiled call) and with
``cmj.Physics.run_bindings`` (the same C calls through the bindings, a lean Python loop). The
window rows, the tail rows (same length) and the brake control must be equal as bytes.
"""
from __future__ import annotations

import hashlib
import sys

import mujoco
import numpy as np
from cmj import Physics

from monitor.gate import Gate, Rollout, hold_ctrl


def compare(m, d, ctrl, nstep, gate, ref: Rollout, proto: Physics, h):
    w_ref = ref._window(d, ctrl, nstep)
    t_ref, brake = ref.brake_rows(d, ctrl, nstep, lambda s: hold_ctrl(m, s), gate.brake_steps,
                                  gate.brake_vel_tol, window_fresh=True)
    ok = True
    for run in (proto.run, proto.run_bindings):  # compiled ctypes calls, then the same calls via the bindings
        w, t, status = run(d, np.asarray(ctrl, dtype=np.float64))
        assert status == 0, status
        ok &= (w.tobytes() == w_ref.tobytes() and t.shape == t_ref.shape and t.tobytes() == t_ref.tobytes()
               and proto.t.ctrl.tobytes() == brake.tobytes())
    h.update(w.tobytes())
    h.update(t.tobytes())
    return ok, len(t) - 1


def tunnel(steps):
    m = mujoco.MjModel.from_xml_path("models/tunnel/scene.xml")
    gate = Gate(m, margin=0.001)
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, 0)
    ref, proto = Rollout(m), Physics(m, 1, gate.brake_steps, gate.brake_vel_tol)
    h, bad, sub = hashlib.sha256(), 0, []
    for k in range(steps):
        target = 0.3 if (k // 100) % 2 == 0 else -0.3
        ctrl = np.clip([12.0 * (target - d.qpos[0])], -6.0, 6.0)
        ok, n = compare(m, d, ctrl, 1, gate, ref, proto, h)
        bad += not ok
        sub.append(n)
        gate.step(d, ctrl, nstep=1)
    print(f"tunnel: {steps} steps, {bad} differ; tail substeps min/median/max "
          f"{min(sub)}/{int(np.median(sub))}/{max(sub)} (cap {gate.brake_steps}); "
          f"rows sha256 {h.hexdigest()[:16]}")
    return bad


def pusher(steps):
    import gymnasium as gym

    from monitor.gym_gate import SafetyGate
    env = SafetyGate(gym.make("Pusher-v5"), pairs="mujoco")
    env.reset(seed=0)
    env.action_space.seed(0)
    u = env.unwrapped
    m, d, gate = u.model, u.data, env.gate
    ref, proto = Rollout(m), Physics(m, u.frame_skip, gate.brake_steps, gate.brake_vel_tol)
    h, bad, sub = hashlib.sha256(), 0, []
    for k in range(steps):
        a = env.action_space.sample()
        ok, n = compare(m, d, np.asarray(a, np.float64), u.frame_skip, gate, ref, proto, h)
        bad += not ok
        sub.append(n)
        _, _, te, tr, _ = env.step(a)
        if te or tr:
            env.reset()
    print(f"pusher: {steps} steps, {bad} differ; tail substeps min/median/max "
          f"{min(sub)}/{int(np.median(sub))}/{max(sub)} (cap {gate.brake_steps}); "
          f"rows sha256 {h.hexdigest()[:16]}")
    return bad


if __name__ == "__main__":
    nt = int(sys.argv[1]) if len(sys.argv) > 1 else 600
    npu = int(sys.argv[2]) if len(sys.argv) > 2 else 300
    bad = tunnel(nt) + pusher(npu)
    sys.exit(1 if bad else 0)
