"""Where a 1000/3000-body window goes: whole certify vs the cull alone vs the prototype's parts.

Usage: PYTHONPATH=<tree> python docs/notes/issue-12-sweep/breakdown.py N [sparse|dense] [translating|rotating]
"""
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(__file__))
import run_sweep as rs  # noqa: E402
import sweep_proto as sp  # noqa: E402

import monitor  # noqa: E402
from monitor.bench.suites import scaling_scene  # noqa: E402

n = int(sys.argv[1])
density = sys.argv[2] if len(sys.argv) > 2 else "sparse"
motion = sys.argv[3] if len(sys.argv) > 3 else "translating"
model, bm = scaling_scene(n, density, motion)
scene = monitor.Scene.from_model(model, pairs="all")
KS, gp, mp, pairs, fixed, moving, rest = rs.capture(scene, bm)
prm, sc = rest[4], rest[9]
T = sc.shape[0]
margin = float(prm[KS.WP_MARGIN])
pol = sp.policy_arrays(model, scene)
P = pairs.shape[0]
code, gap, surv = np.empty(P, np.int64), np.empty(P), np.empty(P, np.int64)
res, info, none = np.empty((1, KS.R_SIZE)), np.zeros(KS.WI_SIZE), np.zeros(0, np.int64)
lo, hi, sc2, sr2, pad = sp.swept_boxes(gp, mp, prm, T)
thr = margin + pad + 1e-9
fns = {
    "whole certify (epsilon 1e-3)": lambda: monitor.certify(scene, bm, epsilon=1e-3),
    "current cull (stage 0, k1 = 0)": lambda: KS.window_kernel(gp, mp, pairs, fixed, moving, none, 0, 0, 0,
                                                              prm, code, gap, surv, res, sc, rest[10], info),
    "proto: swept_boxes only": lambda: sp.swept_boxes(gp, mp, prm, T),
    "proto: sweep_pairs only": lambda: sp.sweep_pairs(lo, hi, thr, *pol),
    "proto: proto_cull (all of it)": lambda: sp.proto_cull(gp, mp, prm, T, margin, *pol),
}
for f in fns.values():
    f()
ts = {k: [] for k in fns}
for _ in range(7):
    for k, f in fns.items():
        t = time.perf_counter()
        f()
        ts[k].append(time.perf_counter() - t)
print(f"{n} bodies, {density}, {motion}: {P} selected pairs, T = {T}")
for k, v in ts.items():
    print(f"  {k:34s} median {np.median(v) * 1e3:8.3f} ms  (min {min(v) * 1e3:.3f})")
