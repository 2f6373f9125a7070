"""Per certify call on the Arm gate: rows, verdict, time, tests, full_search/python_stages time."""
import sys, time, collections, statistics, pickle
import numpy as np, gymnasium as gym
import monitor, monitor.envs  # noqa
import monitor.certify.engine as E
from monitor.gym_gate import SafetyGate
eps, nsteps = int(sys.argv[1]), int(sys.argv[2])
pc = time.thread_time
cur = {}
def wrap(name):
    f = getattr(E, name)
    def w(*a, **k):
        t = pc()
        try: return f(*a, **k)
        finally: cur[name] = cur.get(name, 0.0) + pc() - t; cur["n_" + name] = cur.get("n_" + name, 0) + 1
    setattr(E, name, w)
for n in ("_window_kernel", "_python_stages", "_full_search", "deepen"): wrap(n)
_c = E.certify
recs = []
def c(scene, plan, *a, **k):
    cur.clear(); t = pc()
    r = _c(scene, plan, *a, **k)
    dt = pc() - t
    recs.append(dict(rows=len(plan.times), verdict=str(r.verdict), us=dt * 1e6, tests=r.stats.get("tests", 0),
                     mix=dict(r.stats.get("checker_mix", {})), **{k: v for k, v in cur.items()}))
    return r
E.certify = c
env = SafetyGate(gym.make("monitor/Arm-v0"))
env.reset(seed=1000); env.action_space.seed(1000)
for _ in range(3): env.step(env.action_space.sample())
recs.clear()
steps = 0
for ep in range(eps):
    env.reset(seed=ep); env.action_space.seed(ep)
    for a in [env.action_space.sample() for _ in range(nsteps)]:
        env.step(a); steps += 1
tot = sum(r["us"] for r in recs)
print(f"steps {steps} certify calls {len(recs)} certify us/step {tot/steps:.0f}")
groups = collections.defaultdict(list)
for r in recs:
    key = (r["rows"], r["verdict"], "FS" if r.get("n__full_search") else "", "PY" if r.get("n__python_stages") else "")
    groups[key].append(r)
for key, rs in sorted(groups.items(), key=lambda kv: -sum(r["us"] for r in kv[1])):
    us = [r["us"] for r in rs]
    print(f"{str(key):40s} n {len(rs):4d} sum/step {sum(us)/steps:7.0f} median {statistics.median(us):8.0f} max {max(us):8.0f} "
          f"tests med {statistics.median([r['tests'] for r in rs]):6.0f} max {max(r['tests'] for r in rs)} "
          f"wk {sum(r.get('_window_kernel',0) for r in rs)*1e6/steps:6.0f} fs {sum(r.get('_full_search',0) for r in rs)*1e6/steps:6.0f} py {sum(r.get('_python_stages',0) for r in rs)*1e6/steps:6.0f} deepen {sum(r.get('deepen',0) for r in rs)*1e6/steps:6.0f}")
pickle.dump(recs, open("/tmp/armtail_recs.pkl", "wb"))
