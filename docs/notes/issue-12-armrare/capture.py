"""Capture the Arm gate's certify calls that reach the Python stages: (scene, plan, args) pickled."""
import sys, time, pickle
import numpy as np, gymnasium as gym
import monitor, monitor.envs  # noqa
import monitor.certify.engine as E
from monitor.gym_gate import SafetyGate
eps, nsteps = int(sys.argv[1]), int(sys.argv[2])
out = sys.argv[3]
flag = {}
_ps = E._python_stages
def ps(*a, **k):
    flag["py"] = flag.get("py", 0) + 1
    flag["todo"] = [(i, ga.name, gb.name) for i, ga, gb in a[9]]
    flag["start_known"] = dict(k.get("start_known") or {})
    return _ps(*a, **k)
E._python_stages = ps
_c = E.certify
caps = []
where = {}
def c(scene, plan, *a, **k):
    flag.clear(); t = time.thread_time()
    r = _c(scene, plan, *a, **k)
    dt = time.thread_time() - t
    if flag.get("py"):
        rec = dict(where=dict(where), us=dt * 1e6, verdict=str(r.verdict), tests=r.stats.get("tests"),
                   mix=dict(r.stats.get("checker_mix", {})), todo=flag["todo"], start_known=flag["start_known"],
                   clearance=r.clearance, earliest=r.earliest_time,
                   witness=None if r.witness is None else (r.witness.time, r.witness.geoms, r.witness.distance))
        print(rec, flush=True)
        try:
            blob = pickle.dumps((scene, plan, a, k))
            rec["blob"] = blob
        except Exception as e:
            print("pickle failed", type(e), e)
        caps.append(rec)
    return r
E.certify = c
env = SafetyGate(gym.make("monitor/Arm-v0"))
env.reset(seed=1000); env.action_space.seed(1000)
for _ in range(3): env.step(env.action_space.sample())
for ep in range(eps):
    env.reset(seed=ep); env.action_space.seed(ep)
    for j, a in enumerate([env.action_space.sample() for _ in range(nsteps)]):
        where.update(ep=ep, step=j)
        env.step(a)
pickle.dump(caps, open(out, "wb"))
print("captured", len(caps))
