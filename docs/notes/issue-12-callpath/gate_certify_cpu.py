"""CPU time per gate-like certify call on fresh Plan objects (captured from SafetyGate steps)."""
import time, sys, cProfile, pstats
import numpy as np, gymnasium as gym
import monitor.envs  # noqa
from monitor.gym_gate import SafetyGate
from monitor.certify import engine
from monitor.motion.plan import Plan
env_id = sys.argv[1] if len(sys.argv) > 1 else "Pusher-v5"
kw = {"pairs": "mujoco"} if "Pusher" in env_id else {}
g = SafetyGate(gym.make(env_id), **kw)
cap = []
real = engine.certify
def spy(scene, plan, *a, **k):
    cap.append((scene, plan, a, k)); return real(scene, plan, *a, **k)
engine.certify = spy
g.reset(seed=0)
rng = np.random.default_rng(0)
for _ in range(20): g.step(g.action_space.sample())
engine.certify = real
items = [(s, (np.asarray(p.times).copy(), np.asarray(p.qpos).copy(), p.model, p.mocap_pos, p.mocap_quat), a, k)
         for s, p, a, k in cap]
def fresh(d):
    return Plan._trusted(d[0].copy(), d[1].copy(), d[2], mocap_pos=d[3].copy(), mocap_quat=d[4].copy())
def one():
    for s, d, a, k in items:
        c = real(s, fresh(d), *a, **k); len(c.pairs)
def plans_only():
    for s, d, a, k in items:
        fresh(d)
one()
R = 15
t = time.process_time()
for _ in range(R): one()
tc = (time.process_time() - t) / R / len(items)
t = time.process_time()
for _ in range(R): plans_only()
tp = (time.process_time() - t) / R / len(items)
print(f"{env_id}: {len(items)} calls; per call CPU: Plan._trusted {tp*1e6:.0f} us, certify+pairs {1e6*(tc-tp):.0f} us")
print("verdicts", sorted(set(str(real(s, fresh(d), *a, **k).verdict) for s, d, a, k in items)))
if len(sys.argv) > 2:
    pr = cProfile.Profile(); pr.enable()
    for _ in range(5): one()
    pr.disable(); pstats.Stats(pr).sort_stats("tottime").print_stats(int(sys.argv[2]))
