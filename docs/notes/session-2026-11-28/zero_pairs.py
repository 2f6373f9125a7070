import time, warnings, numpy as np, gymnasium as gym, cProfile, pstats
from monitor.gym_gate import SafetyGate
warnings.simplefilter("ignore")
env = SafetyGate(gym.make("Reacher-v5")); raw = gym.make("Reacher-v5")
for e in (env, raw): e.reset(seed=0)
acts = [env.action_space.sample() for _ in range(2000)]
def run(e, n=2000):
    t = time.perf_counter()
    for a in acts[:n]:
        _, _, te, tr, _ = e.step(a)
        if te or tr: e.reset()
    return (time.perf_counter() - t) / n * 1e6
run(env, 50); run(raw, 50)
print("gated us", run(env), "ungated us", run(raw))
pr = cProfile.Profile(); pr.enable(); run(env, 500); pr.disable()
pstats.Stats(pr).sort_stats("tottime").print_stats(14)
