"""Cost of the per-step model checks, each alone (hot loop, plain timers), and their calls per step."""

import collections
import functools
import timeit

import gymnasium as gym

import monitor.certify.kernels as KK
import monitor.gate as G
import monitor.gym_gate as GG
import monitor.motion.pack as PK
import monitor.motion.plan as P
import monitor.scene as S
from monitor.warmup import ensure_warm

ensure_warm()
env = GG.SafetyGate(gym.make("Pusher-v5"), pairs="mujoco")
env.reset(seed=0)
env.action_space.seed(0)
for _ in range(3):
    env.step(env.action_space.sample())
m = env.unwrapped.model
d = env.unwrapped.data
gate = env.gate
scene = gate.scene
snap = scene._snapshot
plan = gate.last_report.plan if hasattr(gate.last_report, "plan") else None
n = 20000


def t(f):
    return min(timeit.repeat(f, number=n, repeat=3)) / n * 1e6


print("plan._structure_key(model)   %.2f us" % t(lambda: P._structure_key(m)))
print("plan._structure(model)       %.2f us" % t(lambda: P._structure(m)))
print("gate._hold_plan(model)       %.2f us" % t(lambda: G._hold_plan(m)))
print("gate.hold_ctrl(model, data)  %.2f us" % t(lambda: G.hold_ctrl(m, d)))
print("scene.sync()                 %.2f us" % t(lambda: scene.sync()))
print("snapshot.unchanged()         %.2f us" % t(lambda: snap.unchanged()))
print("gate._rollout_is_exact       %.2f us" % t(lambda: G._rollout_is_exact(m)))
print("gate.brake_steps             %.2f us" % t(lambda: gate.brake_steps))
# calls per step
cnt = collections.Counter()


def wrap(owner, name):
    f = getattr(owner, name)

    @functools.wraps(f)
    def w(*a, **k):
        cnt[name] += 1
        return f(*a, **k)

    setattr(owner, name, w)


for o, nm in [
    (P, "_structure_key"),
    (G, "_hold_plan"),
    (S.Scene, "sync"),
    (type(snap), "unchanged"),
    (KK, "_pack_agrees"),
    (PK, "static_key"),
    (PK, "plan_data_agrees"),
]:
    wrap(o, nm)
for _ in range(100):
    _, _, te, tr, _ = env.step(env.action_space.sample())
    if te or tr:
        env.reset()
print("calls per step:", {k: v / 100 for k, v in cnt.items()})
