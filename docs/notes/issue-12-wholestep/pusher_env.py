"""Pusher-v5: the ungated ``env.step`` against its own physics (5 x ``mj_step``) and one substep.

Usage: PYTHONPATH=$PWD python docs/notes/issue-12-wholestep/pusher_env.py STEPS ROUNDS

Interleaved blocks (order rotated per round), seeded uniform actions (seed 0):
* ``env.step``: ``gym.make("Pusher-v5").step(a)`` (the bench's ungated reference: wrappers, obs, reward);
* ``5 x mj_step``: ``data.ctrl[:] = a`` and the frame_skip substeps through the bindings, from the same
  states (``mj_setState`` outside the timer).
Prints medians over rounds of the per-step means (µs), and the env's own Python (the difference).
"""
from __future__ import annotations

import gc
import statistics
import sys
import time

import gymnasium as gym
import mujoco
import numpy as np

ns = time.perf_counter_ns


def main():
    steps, rounds = int(sys.argv[1]), int(sys.argv[2])
    env = gym.make("Pusher-v5")
    u = env.unwrapped
    m, d = u.model, u.data
    env.action_space.seed(0)
    acts = [env.action_space.sample() for _ in range(steps)]
    sig = mujoco.mjtState.mjSTATE_INTEGRATION
    states = []

    def env_block():
        env.reset(seed=0)
        states.clear()
        tot = 0
        for a in acts:
            st = np.empty(mujoco.mj_stateSize(m, sig))
            mujoco.mj_getState(m, d, st, sig)
            states.append(st)
            t = ns()
            env.step(a)
            tot += ns() - t
        return tot / steps / 1e3

    def phys_block():
        d2 = mujoco.MjData(m)
        tot = 0
        for st, a in zip(states, acts):
            mujoco.mj_setState(m, d2, st, sig)
            t = ns()
            d2.ctrl[:] = a
            for _ in range(u.frame_skip):
                mujoco.mj_step(m, d2)
            tot += ns() - t
        return tot / steps / 1e3

    env_block()
    res = {"env.step": [], "5 x mj_step": []}
    for r in range(rounds):
        for name, f in ((("env.step", env_block), ("5 x mj_step", phys_block)) if r % 2 == 0
                        else (("5 x mj_step", phys_block), ("env.step", env_block))):
            if name == "5 x mj_step" and not states:
                env_block()
            gc.collect()
            gc.disable()
            res[name].append(f())
            gc.enable()
    e, p = statistics.median(res["env.step"]), statistics.median(res["5 x mj_step"])
    print(f"Pusher-v5, {steps} steps x {rounds} rounds: env.step {e:.1f} µs, 5 x mj_step {p:.1f} µs "
          f"(one substep {p / 5:.2f} µs), env Python {e - p:.1f} µs")
    for k, v in res.items():
        print(f"  {k}: {[round(x, 1) for x in v]}")


if __name__ == "__main__":
    main()
