"""Hot per-call cost of the Plan build / pack / certify parts on a gate's own windows (µs, median).

Usage (from the tree root): PYTHONPATH=$PWD python docs/notes/issue-12-gatepath/parts.py tunnel|arm|hand30 [STEPS] [REPS]

Runs the workload's gate for STEPS steps, recording the arguments of every ``Plan._trusted`` call
(the gate's window, tail and joint plans); then times each part on those inputs, REPS rounds
over all recorded calls, each part on fresh Plans (the gate never certifies one Plan twice).
"""
from __future__ import annotations

import statistics
import sys
import time

import mujoco
import numpy as np

from monitor.warmup import ensure_warm

ensure_warm()
from monitor.certify import engine  # noqa: E402
from monitor.certify import kernels as KS  # noqa: E402
from monitor.motion import pack as PK  # noqa: E402
from monitor.motion import plan as PL  # noqa: E402

kind = sys.argv[1]
steps = int(sys.argv[2]) if len(sys.argv) > 2 else 200
reps = int(sys.argv[3]) if len(sys.argv) > 3 else 5
rec = []
orig = PL.Plan.__dict__["_trusted"].__func__


def spy(cls, times, qpos, model, **kw):
    rec.append((times.copy(), qpos.copy(), model, {k: v.copy() if isinstance(v, np.ndarray) else v
                                                    for k, v in kw.items()}))
    return orig(cls, times, qpos, model, **kw)


PL.Plan._trusted = classmethod(spy)
if kind in ("tunnel", "hand30"):
    from monitor.bench.targets import _scene_file
    from monitor.gate import Gate
    model = mujoco.MjModel.from_xml_path(str(_scene_file(kind)))
    d = mujoco.MjData(model)
    if kind == "tunnel":
        gate = Gate(model, margin=0.001)
        mujoco.mj_resetDataKeyframe(model, d, 0)
        for k in range(steps):
            target = 0.3 if (k // 100) % 2 == 0 else -0.3
            gate.step(d, np.clip([12.0 * (target - d.qpos[0])], -6.0, 6.0), nstep=1)
    else:
        gate = Gate(model)
        lo, hi = model.actuator_ctrlrange[:, 0], model.actuator_ctrlrange[:, 1]
        tg = np.random.default_rng(0).uniform(lo, hi, size=(64, model.nu))
        for k in range(steps):
            gate.step(d, tg[(k // 10) % 64], nstep=5)
else:
    import gymnasium as gym

    import monitor.envs  # noqa: F401
    from monitor.gym_gate import SafetyGate
    env = SafetyGate(gym.make("monitor/Arm-v0"), pairs="mujoco")
    env.reset(seed=0)
    env.action_space.seed(0)
    for _ in range(steps):
        env.step(env.action_space.sample())
    gate = env.gate
PL.Plan._trusted = classmethod(orig)
scene, req = gate.scene, gate.request
print(f"{kind}: {len(rec)} Plan._trusted calls over {steps} steps; K median "
      f"{statistics.median(len(r[0]) for r in rec)}")


def fresh():
    return [orig(PL.Plan, t.copy(), q.copy(), m, **{k: v.copy() for k, v in kw.items()}) for t, q, m, kw in rec]


ns = time.perf_counter_ns
res: dict[str, list[float]] = {}


def timeit(label, fn, items):
    t = ns()
    for it in items:
        fn(it)
    res.setdefault(label, []).append((ns() - t) / len(items) / 1e3)


for r in range(reps):
    args = [(t.copy(), q.copy(), m, {k: v.copy() for k, v in kw.items()}) for t, q, m, kw in rec]
    timeit("Plan._trusted", lambda a: orig(PL.Plan, a[0], a[1], a[2], **a[3]), args)
    timeit("_structure_key", lambda a: PL._structure_key(a[2]), args)
    plans = fresh()
    timeit("pack_trajectory", PK.pack_trajectory, plans)
    plans = fresh()
    packs = [PK.pack_trajectory(p) for p in plans]
    timeit("_pack_agrees", lambda pm: KS._pack_agrees(pm[0], pm[1]), list(zip(plans, packs)))
    timeit("static_key", lambda pm: PK.static_key(pm[1], KS._pack_static(pm[0])), list(zip(plans, packs)))
    timeit("plan_data_agrees", lambda pm: PK.plan_data_agrees(pm[0], pm[1]), list(zip(plans, packs)))
    plans = fresh()
    timeit("trajectory_pack_memo", KS.trajectory_pack_memo, plans)
    plans = fresh()
    timeit("certify (fresh plan)", lambda p: engine.certify(scene, p, request=req), plans)
    timeit("certify (same plan again)", lambda p: engine.certify(scene, p, request=req), plans[:1] * len(plans))
    timeit("scene.sync", lambda p: scene.sync(), plans)
for k, v in res.items():
    print(f"{k:28s} {statistics.median(v):8.2f} µs  (rounds {[round(x, 1) for x in v]})")
