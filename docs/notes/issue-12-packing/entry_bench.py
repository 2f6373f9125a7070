"""Fixed Python cost of one compiled-path ``certify`` (issue 12 items 1, 6; brief h12r).

Usage: PYTHONPATH=<tree> python entry_bench.py [reps]   -> one JSON line per case:
  total_us   median wall time of one certify call
  kernel_us  median time inside the compiled calls (window_kernel + pair_window, dispatch included)
  python_us  median of (total - kernel) per call
Cases: (a) culled.py: first 'rotating' bench case, 1 pair, whole-shape violation;
       (b) the first 'rotating' case whose pair is culled;
       (c) Pusher-v5 gate windows: the certify calls SafetyGate(pairs='mujoco') made in 12 steps,
           replayed (same scene and plan objects: packs warm).
"""
import json
import sys
import time

import numpy as np

reps = int(sys.argv[1]) if len(sys.argv) > 1 else 300
import monitor.certify.engine as E  # noqa: E402
from monitor.bench.cases import make_cases  # noqa: E402
from monitor.certify import kernels as KS  # noqa: E402

acc = [0.0]
_wk, _pw = KS.window_kernel, KS.pair_window


def wk(*a):
    t = time.perf_counter()
    try:
        return _wk(*a)
    finally:
        acc[0] += time.perf_counter() - t


def pw(*a):
    t = time.perf_counter()
    try:
        return _pw(*a)
    finally:
        acc[0] += time.perf_counter() - t


import os  # noqa: E402
import pickle  # noqa: E402

CACHE = os.environ.get("ENTRY_CASES", "/tmp/entry_bench_cases.pkl")  # make_cases takes ~20 s
if os.path.exists(CACHE):
    with open(CACHE, "rb") as f:
        calls = pickle.load(f)
else:
    cases = make_cases(seed=7, quick=True)
    rot = [c for c in cases if c.group == "rotating"]
    calls = {}
    s, m = rot[0].scene(16), rot[0].body_motion()
    calls["a_culledpy"] = [(s, m, dict(margin=0.0, epsilon=1e-3, method="toleranced"))]
    for c in rot:
        s, m = c.scene(16), c.body_motion()
        cert = E.certify(s, m, margin=0.0, epsilon=1e-3, method="toleranced")
        if cert.stats["checker_mix"] == {"culled": 1}:
            calls["b_culled_pair"] = [(s, m, dict(margin=0.0, epsilon=1e-3, method="toleranced"))]
            break
    with open(CACHE, "wb") as f:
        pickle.dump(calls, f)

import gymnasium as gym  # noqa: E402

import monitor.envs  # noqa: E402,F401
from monitor.gym_gate import SafetyGate  # noqa: E402

rec = []
_orig = E.certify


def recording(scene, plan, *a, **kw):
    rec.append((scene, plan, dict(kw)))
    return _orig(scene, plan, *a, **kw)


E.certify = recording
g = SafetyGate(gym.make("Pusher-v5"), pairs="mujoco")
g.reset(seed=0)
rng = np.random.default_rng(0)
for _ in range(12):
    g.step(g.action_space.sample())
E.certify = _orig
calls["c_pusher"] = rec[-12:]

for cl in calls.values():   # compile (or load) every kernel before the wrappers replace the module
    for sc, pl, kw in cl:    # globals: jitted callers of pair_window must not see the wrapper
        E.certify(sc, pl, **dict(kw, budget=None) if "budget" in kw else kw)
KS.window_kernel, KS.pair_window = wk, pw
out = {}
for name, cl in calls.items():
    for sc, pl, kw in cl:   # warm
        for _ in range(20):
            E.certify(sc, pl, **kw)
    tot, ker = [], []
    for _ in range(reps):
        for sc, pl, kw in cl:
            if "budget" in kw:
                kw = dict(kw, budget=None)  # a Budget object's clock would run out between replays
            acc[0] = 0.0
            t = time.perf_counter()
            cert = E.certify(sc, pl, **kw)
            tot.append(time.perf_counter() - t)
            ker.append(acc[0])
    tot, ker = np.array(tot) * 1e6, np.array(ker) * 1e6
    out[name] = dict(total_us=float(np.median(tot)), kernel_us=float(np.median(ker)),
                     python_us=float(np.median(tot - ker)), n=len(tot), verdict=str(cert.verdict),
                     mix=cert.stats["checker_mix"])
print(json.dumps(out))
