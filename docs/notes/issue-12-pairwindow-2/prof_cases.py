"""cProfile the bench's pair-window calls (run_ours' exact call: Budget(seconds=...) per call).

Usage: PYTHONPATH=<tree> python prof_cases.py [case-substring] [n]
"""
import cProfile
import pstats
import sys
import time

import numpy as np

import monitor  # noqa: F401
from monitor.bench.cases import make_cases
from monitor.certify.common import Budget
from monitor.certify.engine import certify

sub = sys.argv[1] if len(sys.argv) > 1 else ""
n = int(sys.argv[2]) if len(sys.argv) > 2 else 300
cases = [c for c in make_cases(seed=7, quick=True) if sub in c.name]
items = [(c.scene(16), c.body_motion()) for c in cases]
for s, m in items:
    certify(s, m, margin=0.0, epsilon=1e-3, method="toleranced", budget=Budget(seconds=30.0))
pr = cProfile.Profile()
pr.enable()
for _ in range(n):
    for s, m in items:
        certify(s, m, margin=0.0, epsilon=1e-3, method="toleranced", budget=Budget(seconds=30.0))
pr.disable()
st = pstats.Stats(pr)
st.sort_stats("tottime").print_stats(30)
