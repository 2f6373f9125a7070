"""Segment times of certify / _certify_fast: inserts `_MK(n)` perf_counter marks before chosen
lines of a COPY of monitor/certify/engine.py (the tree's file is not changed), runs one
entry_bench.py case and prints the median µs between consecutive marks.
Usage: PYTHONPATH=<tree> python entry_marks.py CASE "L1,L2,..." [reps]"""
import sys
import time

import numpy as np

case, marks = sys.argv[1], [int(x) for x in sys.argv[2].split(",")]
nrep = int(sys.argv[3]) if len(sys.argv) > 3 else 2000
sys.argv = [sys.argv[0], "1"]
exec(open(__file__.replace("entry_marks.py", "entry_bench.py")).read())
E = sys.modules["monitor.certify.engine"]
src = open(E.__file__).read().split("\n")
T: list = []
for ln in sorted(marks, reverse=True):
    line = src[ln - 1]
    ind = line[:len(line) - len(line.lstrip())]
    src.insert(ln - 1, f"{ind}_MK({ln})")
code = compile("\n".join(src), E.__file__, "exec")
E.__dict__["_MK"] = lambda n: T.append((n, time.perf_counter()))
exec(code, E.__dict__)
cl = calls[case]  # noqa: F821
seg: dict = {}
for _ in range(nrep):
    for sc, pl, kw in cl:
        T.clear()
        E.certify(sc, pl, **kw)
        for (a, ta), (b, tb) in zip(T, T[1:]):
            seg.setdefault((a, b), []).append(tb - ta)
tot = 0.0
for (a, b), v in seg.items():
    med = float(np.median(v)) * 1e6
    tot += med * len(v) / (nrep * len(cl))
    print(f"{a:5d} -> {b:5d}  {med:7.2f} us  (n={len(v)})")
print(f"sum of medians (weighted) {tot:.1f} us")
