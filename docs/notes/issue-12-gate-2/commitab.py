import statistics, sys, time, timeit
import numpy as np, mujoco, gymnasium as gym
import monitor.envs  # noqa
from monitor.gym_gate import SafetyGate
import monitor.gate as G
work = sys.argv[1]
kw = {"pairs": "mujoco"} if "Pusher" in work else {}
env = SafetyGate(gym.make(work), **kw); env.reset(seed=0); env.action_space.seed(0)
a = env.action_space.sample()
env.step(a)
u = env.unwrapped; ro = env.gate._rollout
# time only the env's step part: decide once, then time _step_env with and without the hook, restoring the state
d = u.data; m = u.model
snap = mujoco.MjData(m); mujoco.mj_copyData(snap, m, d)
rep = env.gate.decide(d, a)
def one(commit):
    mujoco.mj_copyData(d, m, snap)
    ro.states(d, rep.applied_ctrl, u.frame_skip)  # scratch holds the window (as after decide)
    t = time.perf_counter()
    if commit:
        u._step_mujoco_simulation = env._commit_sim
    try:
        env._step_env(rep.applied_ctrl)
    finally:
        if commit: del u._step_mujoco_simulation
    return time.perf_counter() - t
res = {True: [], False: []}
for _ in range(400):
    for c in (True, False): res[c].append(one(c))
print(work, {c: f"{statistics.median(v)*1e6:.1f} us" for c, v in res.items()}, "committed", env.gate.stats["committed"])
