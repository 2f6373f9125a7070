"""pyinstrument (0.2 ms) of 20 x 30 gated Pusher steps: `pyi.py pyi` (PYTHONPATH +/tmp/pp), `pyi.py time`."""

import sys
import time
import gc
import gymnasium as gym
from monitor.gym_gate import SafetyGate
from monitor.warmup import ensure_warm

ensure_warm()
env = SafetyGate(gym.make("Pusher-v5"), pairs="mujoco")


def block(n, rep):
    env.reset(seed=rep)
    env.action_space.seed(rep)
    acts = [env.action_space.sample() for _ in range(n)]
    for a in acts:
        _, _, te, tr, info = env.step(a)
        if te or tr:
            env.reset()


block(5, 1000)
gc.collect()
mode = sys.argv[1]
if mode == "pyi":
    from pyinstrument import Profiler

    p = Profiler(interval=0.0002)
    p.start()
    for r in range(20):
        block(30, r)
    p.stop()
    print(p.output_text(unicode=False, color=False, show_all=True))
else:
    ts = []
    for r in range(20):
        t = time.thread_time()
        block(30, r)
        ts.append((time.thread_time() - t) / 30)
    ts.sort()
    print("median us/step", ts[len(ts) // 2] * 1e6)
