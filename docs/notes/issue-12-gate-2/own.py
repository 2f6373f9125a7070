"""The gate's own cost (certify replayed from a recording, ~0 µs) with and without the braking tail."""
import statistics, sys, time
import numpy as np, gymnasium as gym
import monitor.envs  # noqa
import monitor.certify.engine as E
from monitor.gym_gate import SafetyGate
work, n, reps = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
real, tape = E.certify, {}
def key(a, k):
    p = a[1]; return (p.times.tobytes(), p.qpos.tobytes(), repr(k.get("pairs")), k.get("margin"), k.get("window"))
def record(*a, **k):
    c = real(*a, **k); c.pairs; tape[key(a, k)] = c; return c
def replay(*a, **k): return tape[key(a, k)]
kw = {"pairs": "mujoco"} if "Pusher" in work else {}
u = gym.make(work); u.reset(seed=0); u.action_space.seed(0); acts = [u.action_space.sample() for _ in range(n)]
def episode(env):
    env.reset(seed=0); t = time.perf_counter()
    for a in acts:
        _, _, te, tr, _ = env.step(a)
        if te or tr: env.reset(seed=0)
    return (time.perf_counter() - t) / n
envs = {b: SafetyGate(gym.make(work), brake=b, **kw) for b in (True, False)}
E.certify = record
for e in envs.values(): episode(e)
E.certify = replay
R = {b: [] for b in envs}; U = []
for _ in range(reps):
    U.append(episode(u))
    for b, e in envs.items(): R[b].append(episode(e))
us = statistics.median(U)
print(work, f"ungated {us*1e6:.0f} us;", "; ".join(f"brake={b}: gate without certify {statistics.median(v)*1e6:.0f} us = {statistics.median(v)/us:.1f}x" for b, v in R.items()))
