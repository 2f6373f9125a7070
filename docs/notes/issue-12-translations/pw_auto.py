"""Median us per bench pair-window (translating group, quick set, method auto, margin 0, eps 1e-3), one tree.

Usage: PYTHONPATH=<tree> python docs/notes/issue-12-translations/pw_auto.py   (alternate the trees)
"""
import numpy as np

from monitor.bench.cases import make_cases
from monitor.bench.suites import run_ours

cases = [c for c in make_cases(7, quick=True) if c.group == "translating"]
for c in cases:
    run_ours(c, "auto", 1e-3, reps=1)
us = [run_ours(c, "auto", 1e-3, reps=7, min_total_s=0.1)["us"] for c in cases]
tol = [run_ours(c, "toleranced", 1e-3, reps=7, min_total_s=0.1)["us"] for c in cases]
print(f"auto median {np.median(us):.0f} us (p90 {np.percentile(us, 90):.0f});",
      f"toleranced median {np.median(tol):.0f} us; auto/toleranced {np.median(us) / np.median(tol):.2f}")
