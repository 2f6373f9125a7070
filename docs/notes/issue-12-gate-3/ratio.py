"""Gated / ungated per step and where a gated step goes (PYTHONPATH = the tree to measure). From ../issue-12-gate-2/ratio.py, plus brake=0.

PYTHONPATH=<tree> python docs/notes/issue-12-gate-3/ratio.py Pusher-v5 100 3 [brake=0]
"""
import statistics, sys, time
import numpy as np, mujoco, gymnasium as gym
import monitor, monitor.envs  # noqa
import monitor.certify.engine as E
import monitor.gate as G
from monitor.motion.plan import Plan
from monitor.gym_gate import SafetyGate
from monitor._paths import scene_path
work, n, reps = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]); brake = not (len(sys.argv) > 4 and sys.argv[4] == "brake=0")
pc = time.perf_counter
T = dict.fromkeys(("win", "tail", "plan", "plan_in_tail", "cert", "ncert", "env"), 0.0)
state = {"in_tail": False}
def wrap(obj, name, key, count=None, flag=None):
    f = getattr(obj, name)
    def w(*a, **k):
        if flag: state[flag] = True
        t = pc()
        try: return f(*a, **k)
        finally:
            T[key] += pc() - t
            if count: T[count] += 1
            if flag: state[flag] = False
    setattr(obj, name, w)
wrap(G.Rollout, "states", "win")
wrap(G.Rollout, "brake_rows" if hasattr(G.Rollout, "brake_rows") else "brake_tail", "tail", flag="in_tail")
wrap(E, "certify", "cert", "ncert")
_tr = Plan.__dict__["_trusted"].__func__
def trusted(cls, *a, **k):
    t = pc(); r = _tr(cls, *a, **k); dt = pc() - t
    T["plan_in_tail" if state["in_tail"] else "plan"] += dt
    return r
Plan._trusted = classmethod(trusted)
if work == "hand30":
    m = mujoco.MjModel.from_xml_path(str(scene_path("hand30")))
    lo, hi = m.actuator_ctrlrange[:, 0], m.actuator_ctrlrange[:, 1]
    targets = np.random.default_rng(0).uniform(lo, hi, size=(64, m.nu))
    def gated():
        gate = G.Gate(m); d = mujoco.MjData(m); mujoco.mj_resetData(m, d)
        gate.step(d, targets[0], nstep=5)
        for k in T: T[k] = 0
        t = pc()
        for k in range(n): gate.step(d, targets[(k // 10) % 64], nstep=5)
        return (pc() - t) / n, gate.summary()
    def ungated():
        d = mujoco.MjData(m); mujoco.mj_resetData(m, d); t = pc()
        for k in range(200):
            d.ctrl[:] = targets[(k // 10) % 64]; mujoco.mj_step(m, d, nstep=5)
        return (pc() - t) / 200
else:
    kw = {"pairs": "mujoco"} if "Pusher" in work else {}
    u = gym.make(work); u.reset(seed=0); u.action_space.seed(0); acts = [u.action_space.sample() for _ in range(n)]
    def gated():
        env = SafetyGate(gym.make(work), brake=brake, **kw); env.reset(seed=0); env.step(acts[0])
        inner = env.env.step
        def st(a):
            t = pc(); r = inner(a); T["env"] += pc() - t; return r
        env.env.step = st
        for k in T: T[k] = 0
        t = pc()
        for a in acts:
            _, _, te, tr, _ = env.step(a)
            if te or tr: env.reset(seed=0)
        return (pc() - t) / n, env.gate.summary()
    def ungated():
        u.reset(seed=0); t = pc()
        for a in acts:
            _, _, te, tr, _ = u.step(a)
            if te or tr: u.reset(seed=0)
        return (pc() - t) / n
rows, U = [], []
for r in range(reps):
    U.append(ungated()); dt, s = gated(); rows.append((dt, {k: v / n for k, v in T.items()}, s))
u_ = statistics.median(U); dt = statistics.median(r[0] for r in rows)
md = {k: statistics.median(r[1][k] for r in rows) for k in T}
tail_sim = md["tail"] - md["plan_in_tail"]; plans = md["plan"] + md["plan_in_tail"]
rest = dt - md["win"] - tail_sim - md["cert"] - md["env"] - plans
s = rows[-1][2]
def f(x): return f"{x*1e6:.0f} us ({x/u_:.2f}x, {x/dt:.0%})"
print(f"{monitor.__file__.split('/monitor/')[0]} {work} brake={brake}: ungated {u_*1e6:.0f} us, gated {dt*1e6:.0f} us = {dt/u_:.1f}x; "
      f"window sim {f(md['win'])}; tail sim {f(tail_sim)}; certify {f(md['cert'])} [{md['ncert']:.2f} calls/step]; "
      f"env.step {f(md['env'])}; Plans {f(plans)}; rest {f(rest)}; gate w/o certify {(dt-md['cert'])/u_:.1f}x; "
      f"joint {s.get('joint', 0)}/{s['windows']} committed {s.get('committed', 0)} replaced {s['replaced']} brake_rej {s['brake_rejected']}")
