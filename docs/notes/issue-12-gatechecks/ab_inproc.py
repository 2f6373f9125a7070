"""In-process A/B of this branch's gate cuts: interleaved blocks with the base's functions patched back in.

Usage: PYTHONPATH=$PWD python docs/notes/issue-12-gatechecks/ab_inproc.py BASE_TREE WORK BLOCKS ROUNDS [--cpu]
WORK: arm | pusher | tunnel | hand30 (the bench's workloads: SafetyGate on monitor/Arm-v0 / Pusher-v5
with bench-seeded blocks of 30 steps; Gate.step on models/tunnel with the README controller, blocks
of 200 windows; Gate.step on models/hand30 with seeded joint targets, blocks of 20 windows).
The old forms are the base tree's own function objects (its ``monitor/gate.py`` and
``monitor/gym_gate.py`` loaded under other module names): ``hold_ctrl``, ``Rollout._window``,
``Rollout._tail_by_rollout`` (with the base's ``_first_at_rest``), ``SafetyGate._as_inner``,
``SafetyGate._check_applied_ctrl`` and ``Gate._split_reuse``.
Each round times BLOCKS blocks per variant, the order alternating; --cpu: thread CPU time.
"""
import importlib.util
import statistics
import sys
import time

import numpy as np

import monitor.envs  # noqa: F401
import monitor.gate as G
import monitor.gym_gate as GG
from monitor.warmup import ensure_warm

ensure_warm()
base, work, blocks, rounds = sys.argv[1], sys.argv[2], int(sys.argv[3]), int(sys.argv[4])
CLOCK = time.thread_time_ns if "--cpu" in sys.argv else time.perf_counter_ns


def load(name, path):
    spec = importlib.util.spec_from_file_location(name, path)
    mod = importlib.util.module_from_spec(spec)
    sys.modules[name] = mod  # (dataclasses look their module up)
    spec.loader.exec_module(mod)
    return mod


BG = load("base_gate", f"{base}/monitor/gate.py")
BGG = load("base_gym_gate", f"{base}/monitor/gym_gate.py")
NEW = (G.hold_ctrl, G.Rollout.__dict__["_window"], G.Rollout.__dict__["_tail_by_rollout"],
       GG.SafetyGate.__dict__["_as_inner"], GG.SafetyGate.__dict__["_check_applied_ctrl"],
       G.Gate.__dict__["_split_reuse"])
OLD = (BG.hold_ctrl, BG.Rollout.__dict__["_window"], BG.Rollout.__dict__["_tail_by_rollout"],
       BGG.SafetyGate.__dict__["_as_inner"], BGG.SafetyGate.__dict__["_check_applied_ctrl"],
       BG.Gate.__dict__["_split_reuse"])
assert all(a is not b for a, b in zip(NEW, OLD))
assert getattr(OLD[3], "_model_untouched", False)


ROLLOUTS = []  # the gate's Rollout: its C-tail buffers differ in layout between the two forms


def use(v):
    for ro in ROLLOUTS:
        ro._tail_bufs = None
    G.hold_ctrl, G.Rollout._window, G.Rollout._tail_by_rollout, GG.SafetyGate._as_inner, \
        GG.SafetyGate._check_applied_ctrl, G.Gate._split_reuse = v


if work in ("arm", "pusher"):
    import gymnasium as gym

    env = GG.SafetyGate(gym.make({"arm": "monitor/Arm-v0", "pusher": "Pusher-v5"}[work]), pairs="mujoco")

    def run(first):
        tot = 0
        for rep in range(first, first + blocks):
            env.reset(seed=rep)
            env.action_space.seed(rep)
            acts = [env.action_space.sample() for _ in range(30)]
            t = CLOCK()
            for a in acts:
                _, _, te, tr, _ = env.step(a)
                if te or tr:
                    env.reset()
            tot += CLOCK() - t
        return tot / (30 * blocks) / 1e3
else:
    import mujoco

    m = mujoco.MjModel.from_xml_path(f"models/{work}/scene.xml")
    gate = G.Gate(m, margin=0.001) if work == "tunnel" else G.Gate(m)
    d = mujoco.MjData(m)
    if work == "tunnel":
        n_win, nstep = 200, 1

        def reset():
            mujoco.mj_resetDataKeyframe(m, d, 0)

        def controller(k):
            return np.clip([12.0 * ((0.3 if (k // 100) % 2 == 0 else -0.3) - d.qpos[0])], -6.0, 6.0)
    else:
        n_win, nstep = 20, 5
        targets = np.random.default_rng(0).uniform(m.actuator_ctrlrange[:, 0], m.actuator_ctrlrange[:, 1],
                                                   size=(64, m.nu))

        def reset():
            mujoco.mj_resetData(m, d)

        def controller(k):
            return targets[(k // 10) % len(targets)]

    def run(first):
        tot = 0
        for _ in range(blocks):
            reset()
            gate.reset()
            for k in range(n_win):
                c = controller(k)
                t = CLOCK()
                gate.step(d, c, nstep=nstep)
                tot += CLOCK() - t
        return tot / (n_win * blocks) / 1e3

ROLLOUTS.append((env.gate if work in ("arm", "pusher") else gate)._rollout)
use(OLD)
run(1000)
use(NEW)
run(1000)
res = {"old": [], "new": []}
for r in range(rounds):
    for name in (("old", "new") if r % 2 == 0 else ("new", "old")):
        use(OLD if name == "old" else NEW)
        res[name].append(run(100 * r))
ratios = [n / o for o, n in zip(res["old"], res["new"])]
print(f"{work}: old median {statistics.median(res['old']):.1f} µs, new {statistics.median(res['new']):.1f} µs; "
      f"new/old per round median {statistics.median(ratios):.4f} (range {min(ratios):.3f}-{max(ratios):.3f}, "
      f"new faster in {sum(x < 1 for x in ratios)}/{len(ratios)})")
