"""Which path each gated step takes (joint certified / joint failed / two calls) and certify calls per step.

PYTHONPATH=<tree> python docs/notes/issue-12-gate-6/paths.py Pusher-v5|monitor/Arm-v0 STEPS
"""
import collections, sys
import gymnasium as gym
import monitor.envs  # noqa
import monitor.certify.engine as E
import monitor.gate as G
from monitor.gym_gate import SafetyGate

work, n = sys.argv[1], int(sys.argv[2])
kw = {"pairs": "mujoco"} if "Pusher" in work else {}
calls = []
_c = E.certify
def certify(scene, plan, **k):
    c = _c(scene, plan, **k)
    calls.append((len(plan.times), c.verdict, c.stats.get("ongoing", 0), c.stats.get("pairs")))
    return c
E.certify = certify
u = gym.make(work); u.reset(seed=0); u.action_space.seed(0); acts = [u.action_space.sample() for _ in range(n)]
env = SafetyGate(gym.make(work), **kw)
env.reset(seed=0)
paths = collections.Counter()
for a in acts:
    calls.clear()
    hint = env.gate._joint_hint
    _, _, te, tr, info = env.step(a)
    r = env.gate.last_report
    paths[(hint, len(calls), str(r.verdict), str(r.brake_verdict), r.replaced,
           tuple((k, str(v), o) for k, v, o, p in calls))] += 1
    if te or tr: env.reset(seed=0)
for k, v in sorted(paths.items(), key=lambda kv: -kv[1]):
    print(v, k)
print(env.gate.summary())
