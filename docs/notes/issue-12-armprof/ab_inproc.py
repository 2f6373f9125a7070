"""In-process A/B of the two cuts: interleaved blocks with the old forms patched back in, same env, same seeds.

Usage: PYTHONPATH=$PWD python docs/notes/issue-12-armprof/ab_inproc.py ENV_ID BLOCKS ROUNDS [--cpu]  (--cpu: thread CPU time)
Old forms: ``engine._M_*`` set to the plain strings (``np.full`` / fancy assignment of a str: exactly
the base's code path) and ``gate._first_at_rest`` replaced by the base's ``max(axis=1)`` rule.
Each round times BLOCKS blocks of 30 bench-seeded steps per variant, alternating the order.
"""
import statistics
import sys
import time

import gymnasium as gym
import numpy as np

import monitor.certify.engine as E
import monitor.envs  # noqa: F401
import monitor.gate as G
from monitor.gym_gate import SafetyGate
from monitor.warmup import ensure_warm

ensure_warm()
CLOCK = time.thread_time_ns if "--cpu" in sys.argv else time.perf_counter_ns
NEW = (E._M_CULLED, E._M_STATIC, E._M_TOLERANCED, E._M_BUDGET, G._first_at_rest)


def old_first_at_rest(qvel, vel_tol):
    stop = np.abs(qvel).max(axis=1) <= vel_tol
    return int(stop.argmax()) if stop.any() else None


OLD = ("culled", "static", "toleranced", "budget", old_first_at_rest)


def use(v):
    E._M_CULLED, E._M_STATIC, E._M_TOLERANCED, E._M_BUDGET, G._first_at_rest = v


env_id, blocks, rounds = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
env = SafetyGate(gym.make(env_id), pairs="mujoco")


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
print(f"{env_id}: old median {statistics.median(res['old']):.1f} µs, new {statistics.median(res['new']):.1f} µs; "
      f"new/old per round median {statistics.median(ratios):.3f} (range {min(ratios):.3f}-{max(ratios):.3f}, "
      f"new faster in {sum(x < 1 for x in ratios)}/{len(ratios)})")
