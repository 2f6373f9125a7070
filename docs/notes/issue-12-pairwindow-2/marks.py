"""Segment times of certify on one bench case: `_MK(n)` perf_counter marks inserted before chosen
lines of a COPY of monitor/certify/engine.py (the tree's file is unchanged); median us per segment.
Usage: PYTHONPATH=<tree> python marks.py CASE "L1,L2,..." [reps]"""
import sys
import time

import numpy as np

import monitor  # noqa: F401
from monitor.bench.cases import make_cases
from monitor.certify.common import Budget
import monitor.certify.engine as E

case, marks = sys.argv[1], [int(x) for x in sys.argv[2].split(",")]
nrep = int(sys.argv[3]) if len(sys.argv) > 3 else 2000
c = [c for c in make_cases(seed=7, quick=True) if c.name == case][0]
s, m = c.scene(16), c.body_motion()
src = open(E.__file__).read().split("\n")
T: list = []
for ln in sorted(marks, reverse=True):
    line = src[ln - 1]
    ind = line[:len(line) - len(line.lstrip())]
    src.insert(ln - 1, f"{ind}_MK({ln})")
code = compile("\n".join(src), E.__file__, "exec")
E.__dict__["_MK"] = lambda n: T.append((n, time.perf_counter()))
exec(code, E.__dict__)
E.certify(s, m, margin=0.0, epsilon=1e-3, method="toleranced", budget=Budget(seconds=1.0))
seg: dict = {}
tots = []
for _ in range(nrep):
    T.clear()
    b = Budget(seconds=1.0)
    t = time.perf_counter()
    E.certify(s, m, margin=0.0, epsilon=1e-3, method="toleranced", budget=b)
    tots.append(time.perf_counter() - t)
    for (a, ta), (bb, tb) in zip(T, T[1:]):
        seg.setdefault((a, bb), []).append(tb - ta)
for (a, bb), v in seg.items():
    print(f"{a:5d} -> {bb:5d}  {float(np.median(v)) * 1e6:7.2f} us  (n={len(v)})")
print(f"total median {1e6 * float(np.median(tots)):.1f} us")
