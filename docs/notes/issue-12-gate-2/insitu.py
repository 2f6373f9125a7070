import statistics, sys, time
import numpy as np, mujoco, gymnasium as gym
import monitor.envs  # noqa
import monitor.gate as G
from monitor.gym_gate import SafetyGate
work, n = sys.argv[1], int(sys.argv[2])
pc = time.perf_counter
S = {"step_t": 0.0, "steps": 0, "rows_t": 0.0, "in": False}
_step = mujoco.mj_step
def step(*a, **k):
    if not S["in"]: return _step(*a, **k)
    t = pc(); r = _step(*a, **k); S["step_t"] += pc() - t; S["steps"] += 1; return r
mujoco.mj_step = step
_br = G.Rollout.brake_rows
def br(*a, **k):
    S["in"] = True; t = pc()
    try: return _br(*a, **k)
    finally: S["rows_t"] += pc() - t; S["in"] = False
G.Rollout.brake_rows = br
kw = {"pairs": "mujoco"} if "Pusher" in work else {}
env = SafetyGate(gym.make(work), **kw); env.reset(seed=0); env.action_space.seed(0)
acts = [env.action_space.sample() for _ in range(n)]
for a in acts:
    _, _, te, tr, _ = env.step(a)
    if te or tr: env.reset(seed=0)
w = env.gate.stats["windows"]
print(f"{work}: per window: brake_rows {S['rows_t']/w*1e6:.0f} us, of which mj_step {S['step_t']/w*1e6:.0f} us = {S['steps']/w:.1f} substeps x {S['step_t']/max(S['steps'],1)*1e6:.1f} us")
