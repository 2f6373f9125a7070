"""How many of the Arm demo's blocks were necessary (issue 13, item 6).

Runs the demo's scripted policy through ``SafetyGate`` (same margin, seed and steps as
``python -m monitor demo``). At every blocked step, an oracle applies the *ungated*
proposal to a scratch copy of the full simulator state and integrates it

* for the proposal's window (``frame_skip`` substeps), and
* for the window followed by the gate's braking tail (hold-position control for
  ``brake_horizon`` = 0.25 s), the question the gate's recoverability check asks,

and records whether a monitored pair (default pair policy) comes closer than 0 (a
collision) or than the margin, by the exact static distance at every substep and at 8
interpolated instants between substeps (dense sampling; a sampled "no" can miss a
graze shorter than the spacing, a sampled "yes" is a confirmed collision). Usage::

    PYTHONPATH=. python scripts/arm_blocks_oracle.py [--steps 150] [--seed 0] [--margin 0.005]
"""

from __future__ import annotations

import argparse
from collections import Counter

import gymnasium as gym
import mujoco
import numpy as np

import envs  # noqa: F401  (registers monitor/Arm-v0)
from monitor.commands.demo import ScriptedPolicy
from monitor.gate import hold_ctrl
from monitor.geometry.distance import shape_distance_batch
from monitor.gym_gate import SafetyGate
from monitor.motion.plan import Plan

_FULL = mujoco.mjtState.mjSTATE_INTEGRATION  # as the gate's rollout: includes ctrl, warm start


def _min_distance(scene, plan) -> tuple[float, tuple[str, str]]:
    """(min exact distance (upper bound) over monitored pairs at dense instants of ``plan``, its pair)."""
    k = len(plan.times)
    ts = np.unique(np.concatenate([np.linspace(plan.times[i], plan.times[i + 1], 9) for i in range(k - 1)]))
    pos, rot = plan.body_poses(ts)
    best, which = np.inf, ("", "")
    for a, b in scene.pair_ids.tolist():
        ga, gb = scene.geoms[a], scene.geoms[b]
        _, up = shape_distance_batch(ga.shape, (rot[:, ga.body_id], pos[:, ga.body_id]),
                                     gb.shape, (rot[:, gb.body_id], pos[:, gb.body_id]))
        v = float((up + ga.shape.approx_error + gb.shape.approx_error).min())
        if v < best:
            best, which = v, (ga.name, gb.name)
    return best, which


def _oracle(model, data, action, nstep, brake_steps):
    """(min distance in the window, min distance in window + braking tail) of the ungated action."""
    s = mujoco.MjData(model)
    st = np.empty(mujoco.mj_stateSize(model, _FULL))
    mujoco.mj_getState(model, data, st, _FULL)
    mujoco.mj_setState(model, s, st, _FULL)
    s.ctrl[:] = action
    times, qpos = [s.time], [s.qpos.copy()]
    for _ in range(nstep):
        mujoco.mj_step(model, s)
        times.append(s.time)
        qpos.append(s.qpos.copy())
    win = Plan(np.array(times), np.array(qpos), model=model)
    s.ctrl[:] = hold_ctrl(model, s)
    for _ in range(brake_steps):
        mujoco.mj_step(model, s)
        times.append(s.time)
        qpos.append(s.qpos.copy())
    tail = Plan(np.array(times), np.array(qpos), model=model)
    return win, tail


def main() -> None:
    """Print the counts."""
    ap = argparse.ArgumentParser()
    ap.add_argument("--steps", type=int, default=150)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--margin", type=float, default=0.005)
    args = ap.parse_args()
    env = gym.make("monitor/Arm-v0", max_episode_steps=max(args.steps, 1))
    gated = SafetyGate(env, margin=args.margin, on_violation="block")
    gate, u = gated.gate, env.unwrapped
    m = u.model
    policy = ScriptedPolicy(np.random.default_rng(args.seed), env.action_space.low, env.action_space.high)
    obs, _ = gated.reset(seed=args.seed)
    rows = []
    for _ in range(args.steps):
        action = policy(obs)
        pre = mujoco.MjData(m)
        st = np.empty(mujoco.mj_stateSize(m, _FULL))
        mujoco.mj_getState(m, u.data, st, _FULL)
        mujoco.mj_setState(m, pre, st, _FULL)
        obs, _, term, trunc, info = gated.step(action)
        s = info["safety"]
        if s["intervened"]:
            win, tail = _oracle(m, pre, np.asarray(action, float), gate.frame_skip, gate.brake_steps)
            (dw, _), (dt, pt) = _min_distance(gate.scene, win), _min_distance(gate.scene, tail)
            rows.append((s["block_reason"], policy.aim, dw, dt, pt))
        if term or trunc:
            obs, _ = gated.reset()
    gated.close()
    n = len(rows)
    print(f"Arm demo oracle: {args.steps} steps, seed {args.seed}, margin {args.margin} m, "
          f"{gate.npairs} monitored pairs; {n} blocked")
    print(f"  blocks by reason: {dict(Counter(r[0] for r in rows))}; "
          f"by aim: {dict(Counter(r[1] for r in rows))}")
    for label, k in (("proposal window", 2), ("window + braking tail", 3)):
        col = sum(1 for r in rows if r[k] < 0.0)
        close = sum(1 for r in rows if r[k] < args.margin)
        print(f"  {label:<22}: collides {col}/{n}, closer than the margin {close}/{n}")
    print(f"  closest pair in window + tail (blocks): {dict(Counter(r[4] for r in rows))}")
    free = [r for r in rows if r[1] == "free"]
    print(f"  blocks while aiming at free space: {len(free)}; of them window+tail < margin "
          f"{sum(r[3] < args.margin for r in free)}, collides {sum(r[3] < 0 for r in free)}; "
          f"closest pairs {dict(Counter(r[4] for r in free))}")
    for reason in sorted({r[0] for r in rows}):
        sub = [r for r in rows if r[0] == reason]
        print(f"    {reason}: window < margin {sum(r[2] < args.margin for r in sub)}/{len(sub)}, "
              f"window+tail < margin {sum(r[3] < args.margin for r in sub)}/{len(sub)}, "
              f"window+tail collides {sum(r[3] < 0 for r in sub)}/{len(sub)}")


if __name__ == "__main__":
    main()
