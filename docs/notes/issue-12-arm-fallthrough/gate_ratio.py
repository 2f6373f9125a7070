"""Gated / ungated monitor/Arm-v0 step time, seeded actions, this branch's engine changes off / on (same process).

off = engine._full_search returns at once and engine._translates always asks plan.translation_segments
(the base commit's behaviour); on = this branch.

Usage: PYTHONPATH=$PWD python docs/notes/issue-12-arm-fallthrough/gate_ratio.py [steps] [rounds]
"""
import statistics
import sys
import time

import gymnasium as gym

import monitor.envs  # noqa: F401
from monitor.certify import engine
from monitor.gym_gate import SafetyGate

n = int(sys.argv[1]) if len(sys.argv) > 1 else 150
rounds = int(sys.argv[2]) if len(sys.argv) > 2 else 2
full = engine._full_search
trans = engine._translates


def switch(on):
    """This branch's two changes on or off."""
    engine._full_search = full if on else (lambda *a, **k: 0)
    engine._translates = trans if on else (lambda plan, mp, b: plan.translation_segments(b) is not None)

u = gym.make("monitor/Arm-v0")
u.action_space.seed(0)
acts = [u.action_space.sample() for _ in range(200)]


def run(env):
    """Wall and CPU seconds per step over n seeded steps."""
    env.reset(seed=0)
    t, c = time.perf_counter(), time.process_time()
    for k in range(n):
        _, _, term, trunc, _ = env.step(acts[k % len(acts)])
        if term or trunc:
            env.reset(seed=0)
    return (time.perf_counter() - t) / n, (time.process_time() - c) / n


gates = {}
for on in (False, True):
    switch(on)
    gates[on] = SafetyGate(gym.make("monitor/Arm-v0"))
    run(gates[on])
switch(True)
run(u)
res = {False: [], True: [], "u": []}
for _ in range(rounds):
    for on in (False, True):
        switch(on)
        res[on].append(run(gates[on]))
    switch(True)
    res["u"].append(run(u))
ucpu = statistics.median(r[1] for r in res["u"])
uw = statistics.median(r[0] for r in res["u"])
for on in (False, True):
    w = statistics.median(r[0] for r in res[on])
    c = statistics.median(r[1] for r in res[on])
    print(f"full_search={'on ' if on else 'off'}: gated {w*1e6:.0f} us wall ({w/uw:.1f}x), "
          f"{c*1e6:.0f} us CPU ({c/ucpu:.1f}x); ungated {uw*1e6:.0f} us wall, {ucpu*1e6:.0f} us CPU")
