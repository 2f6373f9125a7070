"""Profilers over 20 x 30 seeded gated Pusher steps (after ``ensure_warm`` and a warm-up block).

Usage: PYTHONPATH=$PWD:/tmp/pp python docs/notes/issue-12-pusherpy/prof_step.py MODE
  MODE ``time``: median thread time per step; ``pyi``: pyinstrument (interval 0.2 ms);
  ``lp``: line_profiler of the step path (``pip install --target /tmp/pp pyinstrument line_profiler``).
"""

import gc
import sys
import time

import gymnasium as gym

import monitor.certify.engine as E
import monitor.gate as G
import monitor.gym_gate as GG
from monitor.warmup import ensure_warm

ensure_warm()
env = GG.SafetyGate(gym.make("Pusher-v5"), pairs="mujoco")


def block(n, rep):
    env.reset(seed=rep)
    env.action_space.seed(rep)
    acts = [env.action_space.sample() for _ in range(n)]
    for a in acts:
        _, _, te, tr, _ = env.step(a)
        if te or tr:
            env.reset()


def blocks():
    for r in range(20):
        block(30, r)


block(5, 1000)
gc.collect()
mode = sys.argv[1]
if mode == "pyi":
    from pyinstrument import Profiler

    p = Profiler(interval=0.0002)
    p.start()
    blocks()
    p.stop()
    print(p.output_text(unicode=False, color=False, show_all=True))
elif mode == "lp":
    from line_profiler import LineProfiler

    lp = LineProfiler()
    for f in (GG.SafetyGate.step, G.Gate.decide, G.Gate._certify_joint, E.certify, E._certify_fast,
              G.Rollout._tail_by_rollout, G.Rollout.brake_rows):
        lp.add_function(f)
    lp.enable_by_count()
    blocks()
    lp.disable_by_count()
    lp.print_stats(output_unit=1e-6, stripzeros=True)
else:
    ts = []
    for r in range(20):
        t = time.thread_time()
        block(30, r)
        ts.append((time.thread_time() - t) / 30)
    ts.sort()
    print("median us/step", ts[len(ts) // 2] * 1e6)
