"""Python-level calls per gated step and a few C / numpy calls, by cProfile counts (not times).

PYTHONPATH=<tree> python docs/notes/issue-12-gate-4/count.py Pusher-v5|monitor/Arm-v0
"""
import sys, cProfile, pstats, io, numpy as np, gymnasium as gym
import monitor.envs  # noqa
from monitor.gym_gate import SafetyGate
env_id = sys.argv[1]; n = 100
kw = {"pairs": "mujoco"} if "Pusher" in env_id else {}
g = SafetyGate(gym.make(env_id), **kw); g.reset(seed=0); g.action_space.seed(0)
acts = [g.action_space.sample() for _ in range(n)]
def run():
    g.reset(seed=0)
    for a in acts:
        _, _, te, tr, _ = g.step(a)
        if te or tr: g.reset(seed=0)
run()
pr = cProfile.Profile(); pr.enable(); run(); pr.disable()
st = pstats.Stats(pr); tot = sum(v[1] for v in st.stats.values())
def c(sub): return sum(v[1] for k, v in st.stats.items() if sub in k[2] or sub in k[0]) / n
import monitor
print(monitor.__file__.split("/monitor/")[0], env_id, f"calls/step {tot/n:.0f}", " ".join(f"{s}:{c(s):.1f}" for s in ("array_equal", "'any'", "'all'", "mj_getState", "mj_setState", "mj_copyData", "gate.py", "gym_gate.py")))
