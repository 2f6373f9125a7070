"""Gated / ungated step time (wall and CPU), 3 interleaved rounds; medians. Same action sequence as /work/wt/prof/pusher.py."""
import time, sys
import numpy as np, gymnasium as gym
import monitor.envs  # noqa
from monitor.gym_gate import SafetyGate
env_id = sys.argv[1]
kw = {"pairs": "mujoco"} if "Pusher" in env_id else {}
g = SafetyGate(gym.make(env_id), **kw); u = gym.make(env_id)
acts = [g.action_space.sample() for _ in range(200)]
def run(env, n):
    env.reset(seed=0); t = time.perf_counter(); c = time.process_time()
    for k in range(n):
        _, _, term, trunc, _ = env.step(acts[k % len(acts)])
        if term or trunc: env.reset(seed=0)
    return (time.perf_counter() - t) / n, (time.process_time() - c) / n
run(g, 5); run(u, 5)
rw, rc, gw, gc_ = [], [], [], []
for _ in range(3):
    tu = run(u, 200); tg = run(g, 100)
    rw.append(tg[0] / tu[0]); rc.append(tg[1] / tu[1]); gw.append(tg[0]); gc_.append(tg[1])
print(f"{env_id}: gated wall {1e6*np.median(gw):.0f} us cpu {1e6*np.median(gc_):.0f} us; ratio wall {np.median(rw):.1f} cpu {np.median(rc):.1f}  (rounds: {', '.join(f'{x:.1f}' for x in rw)})")
