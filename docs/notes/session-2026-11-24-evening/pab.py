import time, sys, numpy as np, gymnasium as gym
import monitor.envs  # noqa
from monitor.gym_gate import SafetyGate
res = {}
for env_id, kw in (("Pusher-v5", {"pairs": "mujoco"}), ("Pusher-v5", {"pairs": "mujoco", "brake": False}), ("monitor/Arm-v0", {})):
    g = SafetyGate(gym.make(env_id), **kw); u = gym.make(env_id)
    g.action_space.seed(0)
    acts = [g.action_space.sample() for _ in range(200)]
    def run(env, n):
        env.reset(seed=0); t = time.perf_counter()
        for k in range(n):
            _, _, term, trunc, _ = env.step(acts[k % len(acts)])
            if term or trunc: env.reset(seed=0)
        return (time.perf_counter() - t) / n
    run(g, 5); run(u, 5)
    r = []
    for _ in range(5):
        tu = run(u, 100); tg = run(g, 40); r.append(tg / tu)
    print(env_id, kw, "ratio median %.2f" % np.median(r), flush=True)
