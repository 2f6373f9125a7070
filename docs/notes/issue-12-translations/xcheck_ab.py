"""The 1000-case cross-check (issue 14) with the compiled first pass on, then off: table and wall time.

Usage: PYTHONPATH=$PWD python docs/notes/issue-12-translations/xcheck_ab.py [n]
"""
import sys
import time

from monitor.bench.cases import make_translating_cases
from monitor.bench.suites import crosscheck_case, crosscheck_summary
from monitor.certify import engine

n = int(sys.argv[1]) if len(sys.argv) > 1 else 1000
cases = make_translating_cases(n, seed0=0)
ext = {}
for flag in (True, False, True, False):  # the first pair warms caches and kernels
    engine._SWEPT_FIRST = flag
    t = time.perf_counter()
    entries = [crosscheck_case(c) for c in cases]
    dt = time.perf_counter() - t
    s = crosscheck_summary(entries)
    ext[flag] = [e["extrusion"]["verdict"] for e in entries]
    print(f"pass {'on ' if flag else 'off'}: {dt:.1f} s; contradictions {s['contradictions']}, "
          f"false negatives {s['false_negatives']}; verdict pairs {s['verdict_pairs']}")
engine._SWEPT_FIRST = True
diff = sum(a != b for a, b in zip(ext[True], ext[False]))
print(f"extrusion verdicts differing between on and off: {diff} of {n}")
