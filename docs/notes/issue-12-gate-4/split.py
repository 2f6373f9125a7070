"""Per gated step: physics (window + tail), certify, Plan, gate Python, SafetyGate wrapper, env.

PYTHONPATH=<tree> python docs/notes/issue-12-gate-4/split.py Pusher-v5|monitor/Arm-v0|tunnel STEPS ROUNDS

Each round: the ungated loop, then the gated one (same actions); medians over rounds.
* physics: every mj_step / mujoco.rollout call made while the gate runs (window, braking tail,
  and a window the env steps itself, e.g. inside the committed tail);
* certify: monitor.certify.engine.certify (incl. its trajectory pack and checks);
* plan: Plan._trusted called by the gate outside certify;
* gate: the rest of Gate.decide (+ Gate.step / SafetyGate._commit_sim: the commit check and copy);
* wrapper: SafetyGate.step minus decide, the env's own step and the commit (action checks,
  info["safety"], the ctrl check);
* env: the wrapped env's step minus its simulation (obs, reward, gymnasium wrappers): ungated pays it too.
Clock: time.thread_time (this thread's CPU time: the machine is shared, wall time counts
the time other processes hold the core). Each round: the ungated loop, the gated loop with no
timer inside (the ratio), then the gated loop again with the part timers on (the split; the
timers add ~1 us per timed call, booked to the part they time).
"""
import statistics, sys, time
import numpy as np, mujoco, gymnasium as gym
import monitor, monitor.envs  # noqa
import monitor.certify.engine as E
import monitor.gate as G
from monitor.motion.plan import Plan
from monitor.gym_gate import SafetyGate

work, n, reps = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
pc = time.thread_time
T = dict.fromkeys(("physics", "certify", "plan", "decide", "commit", "envstep", "step"), 0.0)
st = {"on": False, "timers": True}

_mj_step = mujoco.mj_step
def mj_step(*a, **k):
    if not (st["on"] and st["timers"]):
        return _mj_step(*a, **k)
    t = pc()
    try: return _mj_step(*a, **k)
    finally: T["physics"] += pc() - t

class RollProxy:
    def __init__(self, r): self.r = r
    def rollout(self, *a, **k):
        if not st["timers"]:
            return self.r.rollout(*a, **k)
        t = pc()
        try: return self.r.rollout(*a, **k)
        finally: T["physics"] += pc() - t

def wrap(obj, name, key):
    f = getattr(obj, name)
    def w(*a, **k):
        if not st["timers"]:
            return f(*a, **k)
        t = pc()
        try: return f(*a, **k)
        finally: T[key] += pc() - t
    setattr(obj, name, w)

wrap(E, "certify", "certify")
_tr = Plan.__dict__["_trusted"].__func__
def trusted(cls, *a, **k):
    if not st["timers"]:
        return _tr(cls, *a, **k)
    t = pc(); r = _tr(cls, *a, **k); T["plan"] += pc() - t; return r
Plan._trusted = classmethod(trusted)
wrap(G.Gate, "decide", "decide")
wrap(SafetyGate, "_commit_sim", "commit")

def patch_roll(ro):
    if ro._roll is not None and not isinstance(ro._roll, RollProxy):
        ro._roll = RollProxy(ro._roll)

if work == "tunnel":
    from monitor._paths import scene_path
    m = mujoco.MjModel.from_xml_path(str(scene_path("tunnel")))
    def ctrl_of(d, k):
        target = 0.3 if (k // 25) % 2 == 0 else -0.3
        return np.clip([12.0 * (target - d.qpos[0])], -6, 6)
    gate = G.Gate(m, margin=0.001)
    wrap(gate, "step", "step")
    def gated():
        d = mujoco.MjData(m); mujoco.mj_resetDataKeyframe(m, d, 0); gate.reset()
        gate.step(d, ctrl_of(d, 0)); patch_roll(gate._rollout)
        for k in T: T[k] = 0.0
        st["on"] = True; t = pc()
        for k in range(n):
            gate.step(d, ctrl_of(d, k))
        dt = (pc() - t) / n; st["on"] = False
        return dt, gate.summary()
    def ungated():
        d = mujoco.MjData(m); mujoco.mj_resetDataKeyframe(m, d, 0); t = pc()
        for k in range(n):
            d.ctrl[:] = ctrl_of(d, k); _mj_step(m, d, nstep=1)
        return (pc() - t) / n
else:
    kw = {"pairs": "mujoco"} if "Pusher" in work else {}
    u = gym.make(work); u.reset(seed=0); u.action_space.seed(0); acts = [u.action_space.sample() for _ in range(n)]
    env = SafetyGate(gym.make(work), **kw)
    inner = env.env.step
    def envstep(a):
        if not st["timers"]:
            return inner(a)
        t = pc()
        try: return inner(a)
        finally: T["envstep"] += pc() - t
    env.env.step = envstep
    wrap(env, "step", "step")
    def gated():
        env.reset(seed=0); env.step(acts[0]); patch_roll(env.gate._rollout)
        for k in T: T[k] = 0.0
        st["on"] = True; t = pc()
        for a in acts:
            _, _, te, tr, _ = env.step(a)
            if te or tr: env.reset(seed=0)
        dt = (pc() - t) / n; st["on"] = False
        return dt, env.gate.summary()
    def ungated():
        u.reset(seed=0); t = pc()
        for a in acts:
            _, _, te, tr, _ = u.step(a)
            if te or tr: u.reset(seed=0)
        return (pc() - t) / n
    mujoco.mj_step = mj_step  # only counted while st["on"] (the gated loop)

mujoco.mj_step = mj_step
ungated(); gated()
rows, U, G_ = [], [], []
for r in range(reps):
    U.append(ungated())
    st["timers"] = False; G_.append(gated()[0]); st["timers"] = True
    dt, s = gated(); rows.append((dt, {k: v / n for k, v in T.items()}))
u_ = statistics.median(U); dt = statistics.median(G_); dtw = statistics.median(r[0] for r in rows)
md = {k: statistics.median(r[1][k] for r in rows) for k in T}
if work == "tunnel":
    gate_py = md["step"] - md["physics"] - md["certify"] - md["plan"]
    parts = {"physics": md["physics"], "certify": md["certify"], "plan": md["plan"], "gate": gate_py}
else:
    # env.step wall includes the commit (gate) and, when not committed, the env's own mj_step (physics)
    env_own = md["envstep"] - md["commit"]
    phys_in_env = 0.0  # counted in physics already (mj_step patched globally while on)
    gate_py = md["decide"] - md["physics"] - md["certify"] - md["plan"] + md["commit"]
    wrapper = md["step"] - md["decide"] - md["envstep"]
    parts = {"physics": md["physics"], "certify": md["certify"], "plan": md["plan"], "gate": gate_py,
             "wrapper": wrapper, "env": env_own}
tree = monitor.__file__.split("/monitor/")[0]
print(f"{tree} {work}: ungated {u_*1e6:.0f} us gated {dt*1e6:.0f} us = {dt/u_:.2f}x (timed run {dtw*1e6:.0f} us) | "
      + " ".join(f"{k} {v*1e6:.0f} ({v/u_:.2f}x)" for k, v in parts.items())
      + f" | windows {s['windows']} joint {s.get('joint', 0)} committed {s.get('committed', 0)} replaced {s['replaced']}")
