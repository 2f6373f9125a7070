"""Compiled first pass vs the Python extrusion checker alone, same process, on seeded translating cases.

Usage: PYTHONPATH=$PWD python docs/notes/issue-12-translations/ab_cases.py [n] [method]
Prints verdict pairs, max |earliest time difference|, clearance differences, time ratios.
"""
import sys
import time
from collections import Counter

import numpy as np

from monitor.bench.cases import make_translating_cases
from monitor.certify import engine
from monitor.certify.engine import certify

n = int(sys.argv[1]) if len(sys.argv) > 1 else 200
method = sys.argv[2] if len(sys.argv) > 2 else "auto"
cases = make_translating_cases(n, seed0=0)
pairs, dts, clr, ratio, stages = Counter(), [], [], [], Counter()
tf, tp = [], []
for case in cases:
    scene, motion = case.scene(), case.body_motion()
    out = {}
    for flag in (True, False, True, False):
        engine._SWEPT_FIRST = flag
        t = time.perf_counter()
        c = certify(scene, motion, margin=case.margin, epsilon=1e-3, method=method)
        (tf if flag else tp).append(time.perf_counter() - t)
        out[flag] = c
    a, b = out[True], out[False]
    pairs[(str(a.verdict), str(b.verdict))] += 1
    stages[(str(a.stats.get("extrusion_stages")), a.stats.get("extrusion", {}).get("swept_kernel", 0))] += 1
    if a.earliest_time is not None and b.earliest_time is not None and a.verdict == b.verdict == "violation":
        dts.append(abs(a.earliest_time - b.earliest_time))
    if a.verdict == b.verdict == "certified":
        clr.append(a.clearance - b.clearance)
    if a.verdict != b.verdict:
        print("DIFF", case.name, case.intent, case.kinds, case.margin, a.verdict, b.verdict, a.earliest_time,
              b.earliest_time)
engine._SWEPT_FIRST = True
print("verdict pairs (compiled first, python only):", dict(pairs))
print("stages:", dict(stages))
if dts:
    print(f"violations: max |earliest diff| {max(dts):.3g} s, median {float(np.median(dts)):.3g}")
if clr:
    print(f"certified: clearance diff (new - old) min {min(clr):.3g} max {max(clr):.3g}")
tf2, tp2 = tf[1::2], tp[1::2]
mf, mp = float(np.median(tf2)), float(np.median(tp2))
print(f"median per call: compiled-first {1e6 * mf:.0f} us, python-only {1e6 * mp:.0f} us,",
      f"ratio {mp / mf:.1f}x")
