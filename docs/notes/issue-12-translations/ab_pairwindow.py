"""Bench pair-windows, translating group (quick set): `auto` / `toleranced` medians, first pass on vs off.

Usage: PYTHONPATH=$PWD python docs/notes/issue-12-translations/ab_pairwindow.py [rounds]
The bench's own runner (monitor.bench.suites.run_ours, margin 0, eps 1e-3) on the quick case set;
each round runs every case with the pass on, then off, then toleranced. Late = earliest time after
the oracle's first collision time (must stay 0); misses = certified on an oracle-collide case.
"""
import sys
from collections import Counter

import numpy as np

from monitor.bench import oracle
from monitor.bench.cases import make_cases
from monitor.bench.suites import run_ours
from monitor.bench.targets import _late
from monitor.certify import engine

rounds = int(sys.argv[1]) if len(sys.argv) > 1 else 3
cases = [c for c in make_cases(7, quick=True) if c.group == "translating"]
labels = [oracle.label(c) for c in cases]
us: dict[str, list[list[float]]] = {"auto-compiled": [], "auto-python": [], "toleranced": []}
verdicts: dict[str, Counter] = {k: Counter() for k in us}
late = Counter()
miss = Counter()
for _ in range(rounds):
    row: dict[str, list[float]] = {k: [] for k in us}
    for c, lab in zip(cases, labels):
        for key, method, flag in (("auto-compiled", "auto", True), ("auto-python", "auto", False),
                                  ("toleranced", "toleranced", True)):
            engine._SWEPT_FIRST = flag
            r = run_ours(c, method, 1e-3, reps=5, min_total_s=0.05)
            row[key].append(r["us"])
            verdicts[key][str(r["verdict"])] += 1
            if lab.label == "collide" and r["verdict"] == "certified":
                miss[key] += 1
            if r["verdict"] != "certified" and _late(r["earliest_time"], lab.hit_time, 1.0):
                late[key] += 1
    for k in us:
        us[k].append(row[k])
engine._SWEPT_FIRST = True
med = {k: float(np.median(np.median(np.array(v), axis=0))) for k, v in us.items()}
print(f"{len(cases)} translating cases x {rounds} rounds; median us per pair-window",
      "(median over rounds per case):")
for k in us:
    print(f"  {k:14s} {med[k]:9.0f} us   verdicts {dict(verdicts[k])}  misses {miss[k]}  late {late[k]}")
print(f"auto python/compiled {med['auto-python'] / med['auto-compiled']:.1f}x; "
      f"compiled vs toleranced {med['auto-compiled'] / med['toleranced']:.2f}x")
