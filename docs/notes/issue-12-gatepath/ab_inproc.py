"""In-process A/B of this branch's cuts: blocks of gate steps alternate between the new code and
the base's behaviour switched back in, in one process (thread CPU time per step, medians).

Usage (from the tree root):
    PYTHONPATH=$PWD python docs/notes/issue-12-gatepath/ab_inproc.py tunnel|arm|hand30|pusher ROUNDS [STEPS]

"old" switches the cuts off (``engine._FINGERPRINT[0] = None``: every new motion pack goes
through numba's dispatcher, as on the base); "new" switches them on. The order of the two
blocks alternates per round; each block replays the same seeded steps from a reset.
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

kind, rounds = sys.argv[1], int(sys.argv[2])
steps = int(sys.argv[3]) if len(sys.argv) > 3 else 100
engine._kernels()
NEW = {"fp": engine._FINGERPRINT[0]}


def switch(on: bool) -> None:
    engine._FINGERPRINT[0] = NEW["fp"] if on else None


if kind in ("tunnel", "hand30"):
    from monitor.bench.targets import _scene_file
    from monitor.gate import Gate
    model = mujoco.MjModel.from_xml_path(str(_scene_file(kind)))
    d = mujoco.MjData(model)
    if kind == "tunnel":
        gate = Gate(model, margin=0.001)

        def block() -> float:
            mujoco.mj_resetDataKeyframe(model, d, 0)
            gate.reset()
            t = time.thread_time_ns()
            for k in range(steps):
                target = 0.3 if (k // 100) % 2 == 0 else -0.3
                gate.step(d, np.clip([12.0 * (target - d.qpos[0])], -6.0, 6.0), nstep=1)
            return (time.thread_time_ns() - t) / steps / 1e3
    else:
        gate = Gate(model)
        lo, hi = model.actuator_ctrlrange[:, 0], model.actuator_ctrlrange[:, 1]
        tg = np.random.default_rng(0).uniform(lo, hi, size=(64, model.nu))

        def block() -> float:
            mujoco.mj_resetData(model, d)
            gate.reset()
            t = time.thread_time_ns()
            for k in range(steps):
                gate.step(d, tg[(k // 10) % 64], nstep=5)
            return (time.thread_time_ns() - t) / steps / 1e3
else:
    import gymnasium as gym

    import monitor.envs  # noqa: F401
    from monitor.gym_gate import SafetyGate
    env = SafetyGate(gym.make({"arm": "monitor/Arm-v0", "pusher": "Pusher-v5"}[kind]), pairs="mujoco")

    def block() -> float:
        env.reset(seed=0)
        env.action_space.seed(0)
        acts = [env.action_space.sample() for _ in range(steps)]
        t = time.thread_time_ns()
        for a in acts:
            _, _, te, tr, _ = env.step(a)
            if te or tr:
                env.reset()
        return (time.thread_time_ns() - t) / steps / 1e3

switch(True)
block()
switch(False)
block()
old, new, ratio = [], [], []
for r in range(rounds):
    order = (True, False) if r % 2 else (False, True)
    got = {}
    for on in order:
        switch(on)
        got[on] = block()
    old.append(got[False])
    new.append(got[True])
    ratio.append(got[True] / got[False])
switch(True)
print(f"{kind}: {rounds} rounds x {steps} steps; old median {statistics.median(old):.1f} µs, new median "
      f"{statistics.median(new):.1f} µs; new/old per round median {statistics.median(ratio):.4f} "
      f"(range {min(ratio):.3f}-{max(ratio):.3f}), new faster in {sum(x < 1 for x in ratio)}/{rounds}")
