import sys, time, statistics
import numpy as np, mujoco, gymnasium as gym
import monitor.envs  # noqa
import monitor.gate as G
from monitor.motion.plan import Plan
from monitor.certify.engine import certify
from monitor.gym_gate import SafetyGate
from monitor._paths import scene_path
work, n = sys.argv[1], int(sys.argv[2])
caps = []
orig = G.Gate._certify_joint
class _P:
    def __init__(self, times, qpos, model): self.times, self.qpos, self.model = times, qpos, model
    @property
    def window(self): return (float(self.times[0]), float(self.times[-1]))
def cap(self, plan, wrows, trows, mp, mq):
    P = lambda r: Plan(np.array(r[:, 0]), np.array(r[:, 1:]), self.model)
    if wrows is not None: caps.append((P(wrows), P(trows)))
    return orig(self, plan, wrows, trows, mp, mq)
G.Gate._certify_joint = cap
if work == "hand30":
    m = mujoco.MjModel.from_xml_path(str(scene_path("hand30")))
    lo, hi = m.actuator_ctrlrange[:, 0], m.actuator_ctrlrange[:, 1]
    targets = np.random.default_rng(0).uniform(lo, hi, size=(64, m.nu))
    gate = G.Gate(m, frame_skip=5); d = mujoco.MjData(m); mujoco.mj_resetData(m, d)
    for k in range(n): gate.step(d, targets[(k // 10) % 64])
else:
    kw = {"pairs": "mujoco"} if "Pusher" in work else {}
    env = SafetyGate(gym.make(work), **kw); env.reset(seed=0); env.action_space.seed(0)
    for k in range(n): env.step(env.action_space.sample())
    gate = env.gate
scene = gate.scene
kw = dict(margin=gate.margin, epsilon=gate.epsilon, ongoing=gate.ongoing, penetration_tol=gate.penetration_tol)
rows = []
TT = []
for plan, tail in caps:
    joint = Plan(np.r_[plan.times, tail.times[1:]], np.r_[plan.qpos, tail.qpos[1:]], plan.model)
    def t(p):
        ts = []
        for _ in range(3):
            p = Plan(np.array(p.times), np.array(p.qpos), p.model)  # fresh: no per-plan caches
            a = time.perf_counter(); c = certify(scene, p, **kw); ts.append(time.perf_counter() - a)
        return min(ts), c
    tw, cw = t(plan); tb, cb = t(tail); tj, cj = t(joint)
    ts = []
    tests = (cw.stats.get("tests", 0) + cb.stats.get("tests", 0), cj.stats.get("tests", 0))
    TT.append(tests)
    for _ in range(3):
        p = Plan(np.array(joint.times), np.array(joint.qpos), joint.model)
        a = time.perf_counter()
        c1 = certify(scene, p, window=plan.window, **kw); c2 = certify(scene, p, window=tail.window, **kw)
        ts.append(time.perf_counter() - a)
    assert c1.verdict == cw.verdict and c2.verdict == cb.verdict, (c1.verdict, cw.verdict, c2.verdict, cb.verdict)
    rows.append((tw, tb, tj, min(ts)))
    print(f"win {tw*1e3:6.2f} ms {cw.verdict:9s} tests {cw.stats.get('tests')} | tail {tb*1e3:6.2f} ms {cb.verdict:9s} tests {cb.stats.get('tests')} ({len(tail.times)-1} sub) | joint {tj*1e3:6.2f} ms {cj.verdict:9s} tests {cj.stats.get('tests')}")
tw, tb, tj, tsp = (statistics.median(r[i] for r in rows) for i in range(4))
print(f"{work}: medians window {tw*1e3:.2f} + tail {tb*1e3:.2f} = {(tw+tb)*1e3:.2f} ms vs joint {tj*1e3:.2f} ms vs two windows of the joint plan {tsp*1e3:.2f} ms ({len(rows)} steps); narrow-phase tests two calls {sum(t[0] for t in TT)} vs joint {sum(t[1] for t in TT)}")
