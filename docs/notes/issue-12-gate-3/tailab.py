"""In-process A/B of the braking tail: C rollout (c_tail=True) vs the mj_step loop, same episode.

Two gates on two copies of the env step the same seeded actions in lockstep; per step the
order (C first / loop first) alternates. Reports are identical (tests/test_gate_reports.py),
so both arms do the same work except the tail's simulator. Prints medians per step of
Rollout.brake_rows and of the whole SafetyGate.step, and their ratios.

PYTHONPATH=$PWD python docs/notes/issue-12-gate-3/tailab.py Pusher-v5 300
"""
import sys, time
import numpy as np, gymnasium as gym
import monitor.envs  # noqa
import monitor.gate as G
from monitor.gym_gate import SafetyGate

env_id, n = sys.argv[1], int(sys.argv[2])
kw = {"pairs": "mujoco"} if "Pusher" in env_id else {}
pc = time.perf_counter
acc = {"tail": 0.0}
orig = G.Rollout.brake_rows
def brake_rows(self, *a, **k):
    t = pc()
    try: return orig(self, *a, **k)
    finally: acc["tail"] += pc() - t
G.Rollout.brake_rows = brake_rows
envs = {}
for c in (True, False):
    e = SafetyGate(gym.make(env_id), **kw); e.gate._rollout.c_tail = c; e.reset(seed=0); envs[c] = e
u = gym.make(env_id); u.action_space.seed(0); acts = [u.action_space.sample() for _ in range(n)]
res = {c: {"tail": [], "step": []} for c in envs}
for k, a in enumerate(acts):
    for c in ((True, False) if k % 2 == 0 else (False, True)):
        e = envs[c]; acc["tail"] = 0.0; t = pc()
        _, _, te, tr, _ = e.step(a)
        res[c]["step"].append(pc() - t); res[c]["tail"].append(acc["tail"])
        if te or tr: e.reset(seed=0)
def md(c, key, skip=5): return float(np.median(res[c][key][skip:])) * 1e6
print(f"{env_id}: tail C {md(True, 'tail'):.0f} us vs loop {md(False, 'tail'):.0f} us "
      f"(x{md(True, 'tail') / md(False, 'tail'):.2f}); step C {md(True, 'step'):.0f} us vs loop "
      f"{md(False, 'step'):.0f} us (x{md(True, 'step') / md(False, 'step'):.2f})")
