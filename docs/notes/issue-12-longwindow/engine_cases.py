"""monitor.certify (engine, auto) on named seeded peers cases: verdict and tests (tree comparison).

Usage: PYTHONPATH=<tree> python docs/notes/issue-12-longwindow/engine_cases.py NAME [NAME ...]
"""
import sys

from monitor.bench.cases import make_cases
from monitor.bench.suites import run_ours

want = set(sys.argv[1:])
for c in make_cases(seed=7, quick=False):
    if c.name in want:
        r = run_ours(c, "auto", 1e-3, 1, budget_s=10.0)
        print(c.name, r["verdict"], r["tests"], r["pair_method"])
