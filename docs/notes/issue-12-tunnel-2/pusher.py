"""SafetyGate(Pusher-v5) vs ungated per step (/work/wt/prof/pusher.py without the profile).

PYTHONPATH=<tree> python docs/notes/issue-12-tunnel-2/pusher.py [rounds] -> median gated us, ratio
"""
import sys
import time

import gymnasium as gym
import numpy as np

import monitor.envs  # noqa: F401
from monitor.gym_gate import SafetyGate

g = SafetyGate(gym.make("Pusher-v5"), pairs="mujoco")
u = gym.make("Pusher-v5")
acts = [g.action_space.sample() for _ in range(200)]


def run(env, n):
    env.reset(seed=0)
    t = time.perf_counter()
    for k in range(n):
        _, _, term, trunc, _ = env.step(acts[k % len(acts)])
        if term or trunc:
            env.reset(seed=0)
    return (time.perf_counter() - t) / n


run(g, 5)
run(u, 5)
rounds = int(sys.argv[1]) if len(sys.argv) > 1 else 5
tu, tg = [], []
for _ in range(rounds):
    tu.append(run(u, 200))
    tg.append(run(g, 100))
print(f"gated {np.median(tg) * 1e6:.0f} us ungated {np.median(tu) * 1e6:.0f} us ratio {np.median(tg) / np.median(tu):.1f}")
