import time, cProfile, pstats, sys, collections
import numpy as np, gymnasium as gym
import monitor.envs  # noqa
from monitor.gym_gate import SafetyGate
env_id = sys.argv[1] if len(sys.argv) > 1 else "Pusher-v5"
kw = {"pairs": "mujoco"} if "Pusher" in env_id else {}
g = SafetyGate(gym.make(env_id), **kw); u = gym.make(env_id)
rng = np.random.default_rng(0)
acts = [g.action_space.sample() for _ in range(200)]
def run(env, n):
    env.reset(seed=0); t = time.perf_counter()
    for k in range(n):
        _, _, term, trunc, _ = env.step(acts[k % len(acts)])
        if term or trunc: env.reset(seed=0)
    return (time.perf_counter() - t) / n
run(g, 5); run(u, 5)
tu = run(u, 200); tg = run(g, 100); print(f"{env_id}: ungated {tu*1e6:.0f} us gated {tg*1e6:.0f} us ratio {tg/tu:.1f}")
pr = cProfile.Profile(); pr.enable(); run(g, 100); pr.disable()
pstats.Stats(pr).sort_stats("cumulative").print_stats(int(sys.argv[2]) if len(sys.argv) > 2 else 50)
