"""Gated / ungated monitor/Arm-v0 step, SEEDED actions (prof/pusher.py samples unseeded ones).

Usage: PYTHONPATH=<tree> python docs/notes/issue-12-longwindow/gate_arm.py [steps] [rounds]
Median over rounds of the mean step time of `steps` steps, after 5 warm-up steps.
"""
import sys
import time

import gymnasium as gym
import numpy as np

import monitor.envs  # noqa: F401
from monitor.gym_gate import SafetyGate

n = int(sys.argv[1]) if len(sys.argv) > 1 else 100
rounds = int(sys.argv[2]) if len(sys.argv) > 2 else 3
g = SafetyGate(gym.make("monitor/Arm-v0"))
u = gym.make("monitor/Arm-v0")
g.action_space.seed(0)
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
tu = float(np.median([run(u, 2 * n) for _ in range(rounds)]))
tg = float(np.median([run(g, n) for _ in range(rounds)]))
print(f"Arm-v0 seeded: ungated {tu * 1e6:.0f} us gated {tg * 1e6:.0f} us ratio {tg / tu:.1f}")
