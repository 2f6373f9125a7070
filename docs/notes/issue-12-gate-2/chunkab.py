import statistics, sys, time
import numpy as np, mujoco, gymnasium as gym
import monitor.envs  # noqa
import monitor.gate as G
from monitor.gym_gate import SafetyGate
work = sys.argv[1]
env = SafetyGate(gym.make(work), **({"pairs": "mujoco"} if "Pusher" in work else {})); env.reset(seed=0); env.action_space.seed(0)
u = env.unwrapped; m, d = u.model, u.data; gate = env.gate; n = u.frame_skip
snaps = []
for k in range(60):
    a = env.action_space.sample()
    s = mujoco.MjData(m); mujoco.mj_copyData(s, m, d); snaps.append((s, np.asarray(a, float)))
    env.step(a)
ro = G.Rollout(m)
def run(chunk):
    G._TAIL_CHUNK = chunk; tot = 0.0; L = 0
    for s, a in snaps:
        ro.states(s, a, n)
        t = time.perf_counter()
        rows, _ = ro.brake_rows(s, a, n, gate._brake_ctrl, gate.brake_steps, gate.brake_vel_tol)
        tot += time.perf_counter() - t; L += len(rows) - 1
    return tot / len(snaps), L / len(snaps)
R = {8: [], 32: []}
for _ in range(7):
    for c in R: R[c].append(run(c))
print(work, {c: f"{statistics.median(x[0] for x in v)*1e6:.0f} us/tail, {v[0][1]:.1f} substeps" for c, v in R.items()})
