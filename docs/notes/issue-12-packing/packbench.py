"""Per-step cost of the motion pack of gate-like plans: Plan._trusted, trajectory_pack (pack + check).

Usage: PYTHONPATH=<tree> python packbench.py [ENV_ID] [N]
Records the joint (window + tail) plans' rows of N gated steps of SafetyGate(ENV_ID), then
times, per row set, Plan._trusted(...) and kernels.trajectory_pack(plan) on fresh plan objects.
Prints medians in us.
"""
import sys
import time

import gymnasium as gym
import numpy as np

import monitor.certify.kernels as KS
import monitor.envs  # noqa: F401
from monitor.gym_gate import SafetyGate
from monitor.motion.plan import Plan

env_id = sys.argv[1] if len(sys.argv) > 1 else "Pusher-v5"
N = int(sys.argv[2]) if len(sys.argv) > 2 else 60
kw = {"pairs": "mujoco"} if "Pusher" in env_id else {}
g = SafetyGate(gym.make(env_id), **kw)
rec = []
orig = Plan._trusted.__func__


def spy(cls, times, qpos, model, **k):
    """Record the rows of every Plan the gate builds."""
    rec.append((times.copy(), qpos.copy(), model, {a: b.copy() for a, b in k.items() if a != "tolerances"}))
    return orig(cls, times, qpos, model, **k)


Plan._trusted = classmethod(spy)
g.reset(seed=0)
g.action_space.seed(0)
for _ in range(N):
    _, _, te, tr, _ = g.step(g.action_space.sample())
    if te or tr:
        g.reset(seed=0)
Plan._trusted = classmethod(orig)
rows = [r for r in rec if r[0].shape[0] > 3] or rec
for t, q, m, k in rows[:3]:
    Plan._trusted(t.copy(), q.copy(), m, **{a: b.copy() for a, b in k.items()})
tb, tp, tc = [], [], []
for _ in range(3):
    for t, q, m, k in rows:
        args = (t.copy(), q.copy(), m)
        kk = {a: b.copy() for a, b in k.items()}
        a = time.perf_counter()
        p = Plan._trusted(*args, **kk)
        b = time.perf_counter()
        mp = KS.trajectory_pack(p)
        c = time.perf_counter()
        assert mp is not None
        tb.append(b - a)
        tp.append(c - b)
        tc.append(c - a)
print(f"{env_id}: {len(rows)} plans (K={rows[0][0].shape[0]}..{max(r[0].shape[0] for r in rows)}): "
      f"Plan._trusted {1e6 * np.median(tb):.1f} us, trajectory_pack {1e6 * np.median(tp):.1f} us, "
      f"sum {1e6 * np.median(tc):.1f} us")
