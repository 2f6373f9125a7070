"""Plain-timer split of a gated Pusher step: thread time per wrapped call (~1 us added per wrapped call).

Usage: PYTHONPATH=$PWD python docs/notes/issue-12-pusherpy/split.py wrap BLOCKS  (`nowrap`: loop only)
"""

import functools
import gc
import statistics
import sys
import time

import gymnasium as gym

import monitor.certify.engine as E
import monitor.certify.kernels as KK
import monitor.gate as G
import monitor.gym_gate as GG
import monitor.motion.pack as PK
import monitor.motion.plan as P
from monitor.gym_gate import SafetyGate
from monitor.warmup import ensure_warm

ensure_warm()
acc = {}


def timed(f, label):
    """``f`` with its thread time added to ``acc[label]``."""

    @functools.wraps(f)
    def w(*a, **k):
        t = time.thread_time_ns()
        try:
            return f(*a, **k)
        finally:
            acc[label] = acc.get(label, 0) + time.thread_time_ns() - t

    return w


def wrap(owner, name, label):
    if owner is P.Plan:  # a classmethod: keep it one
        setattr(owner, name, classmethod(timed(owner.__dict__[name].__func__, label)))
    else:
        setattr(owner, name, timed(getattr(owner, name), label))


targets = [
    (GG.SafetyGate, "step", "SafetyGate.step"),
    (G.Gate, "decide", "Gate.decide"),
    (G.Rollout, "_window", "Rollout._window"),
    (G.Rollout, "brake_rows", "Rollout.brake_rows"),
    (G.Rollout, "_tail_by_rollout", "  _tail_by_rollout"),
    (G.Gate, "_brake_ctrl", "  Gate._brake_ctrl"),
    (G._Tail, "__init__", "_Tail()"),
    (G._WindowRows, "__init__", "_WindowRows()"),
    (G.Gate, "_certify_joint", "Gate._certify_joint"),
    (P.Plan, "_trusted", "  Plan._trusted (joint plan)"),
    (G.Gate, "_certify", "  Gate._certify"),
    (E, "certify", "    engine.certify"),
    (E, "_fast_inputs", "      _fast_inputs"),
    (E, "_fast_prep", "      _fast_prep"),
    (E, "_certify_fast", "      _certify_fast"),
    (E, "_all_culled", "        _all_culled"),
    (KK, "_pack_agrees", "        _pack_agrees"),
    (PK, "pack_trajectory", "        pack_trajectory"),
    (PK, "_derive_and_scale", "          _derive_and_scale (numba)"),
    (E, "_window_kernel", "        _window_kernel (numba)"),
    (GG.SafetyGate, "_step_env", "SafetyGate._step_env"),
    (GG.SafetyGate, "_commit_sim", "  _commit_sim"),
    (G.StepReport, "info", "StepReport.info"),
    (GG.SafetyGate, "_check_window_ran", "_check_window_ran"),
    (GG.SafetyGate, "_live_frame_skip", "_live_frame_skip"),
    (G.Gate, "_sync_scene", "Gate._sync_scene"),
]
if sys.argv[1] == "wrap":
    for t in targets:
        wrap(*t)
env = SafetyGate(gym.make("Pusher-v5"), pairs="mujoco")


def block(n, rep):
    env.reset(seed=rep)
    env.action_space.seed(rep)
    acts = [env.action_space.sample() for _ in range(n)]
    t = time.thread_time_ns()
    for a in acts:
        _, _, te, tr, info = env.step(a)
        if te or tr:
            env.reset()
    return (time.thread_time_ns() - t) / n / 1e3


block(5, 1000)
gc.collect()
acc.clear()
per = [block(30, r) for r in range(int(sys.argv[2]))]
N = 30 * len(per)
print(f"step loop median {statistics.median(per):.1f} us/step (blocks {len(per)})")
for _, _, lab in targets:
    if lab in acc:
        print(f"{lab:28s} {acc[lab] / N / 1e3:8.1f} us/step")
