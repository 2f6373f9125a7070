"""Record the certify calls of a seeded monitor/Arm-v0 gated episode; keep those slower than 20 ms.

Usage: PYTHONPATH=$PWD python docs/notes/issue-12-arm-fallthrough/record.py [steps] [out.pkl]
Saves [(scene_model_xml?, ...)] -- the calls are kept in-process by replay.py via record().
"""
import sys
import time

import gymnasium as gym
import numpy as np

import monitor.envs  # noqa: F401
from monitor.certify import engine
from monitor.gym_gate import SafetyGate


def record(steps=150, seed=0, slow_ms=20.0):
    calls = []
    orig = engine.certify

    def wrapped(scene, plan, *a, **k):
        t = time.perf_counter()
        c = orig(scene, plan, *a, **k)
        dt = (time.perf_counter() - t) * 1e3
        calls.append((dt, scene, plan, a, dict(k), c))
        return c

    engine.certify = wrapped
    try:
        g = SafetyGate(gym.make("monitor/Arm-v0"))
        g.action_space.seed(seed)
        acts = [g.action_space.sample() for _ in range(200)]
        g.reset(seed=seed)
        for k in range(steps):
            _, _, term, trunc, _ = g.step(acts[k % len(acts)])
            if term or trunc:
                g.reset(seed=seed)
    finally:
        engine.certify = orig
    return g, calls


if __name__ == "__main__":
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 150
    g, calls = record(n)
    slow = [c for c in calls if c[0] > 20]
    print(f"{len(calls)} calls, {len(slow)} > 20 ms; times ms:", sorted(round(c[0], 1) for c in calls)[-12:])
    for dt, scene, plan, a, k, c in slow:
        print(f"{dt:.1f} ms verdict={c.verdict} mix={c.stats['checker_mix']} tests={c.stats['tests']}")
