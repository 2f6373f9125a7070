"""Gated / ungated step time of SafetyGate(ENV) (the timing half of /work/wt/prof/pusher.py, no profile).

Usage: PYTHONPATH=<tree> python pusher_ratio.py [ENV_ID] [N]
"""
import sys
import time

import gymnasium as gym
import numpy as np

import monitor.envs  # noqa: F401
from monitor.gym_gate import SafetyGate

env_id = sys.argv[1] if len(sys.argv) > 1 else "Pusher-v5"
N = int(sys.argv[2]) if len(sys.argv) > 2 else 200
kw = {"pairs": "mujoco"} if "Pusher" in env_id else {}
g = SafetyGate(gym.make(env_id), **kw)
u = gym.make(env_id)
g.action_space.seed(0)
acts = [g.action_space.sample() for _ in range(200)]


def run(env, n):
    """Mean seconds per step over n steps."""
    env.reset(seed=0)
    t = time.perf_counter()
    for k in range(n):
        _, _, term, trunc, _ = env.step(acts[k % len(acts)])
        if term or trunc:
            env.reset(seed=0)
    return (time.perf_counter() - t) / n


run(g, 5)
run(u, 5)
tu, tg = [], []
for _ in range(3):
    tu.append(run(u, N))
    tg.append(run(g, N // 2))
tu, tg = float(np.median(tu)), float(np.median(tg))
print(f"{env_id}: ungated {tu * 1e6:.0f} us gated {tg * 1e6:.0f} us ratio {tg / tu:.2f}")
