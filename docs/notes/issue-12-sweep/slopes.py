"""Fitted and local log-log slopes of the two timing columns of run_sweep.py's table.

Usage: python docs/notes/issue-12-sweep/slopes.py TABLE.md
"""
import sys
from collections import defaultdict

import numpy as np

rows = defaultdict(list)
for line in open(sys.argv[1]):
    c = [x.strip() for x in line.strip().strip("|").split("|")]
    if len(c) < 12 or not c[2].isdigit():
        continue
    rows[(c[0], c[1])].append((int(c[2]), float(c[9]), float(c[10])))
print("| motion | density | column | fit 10-1000 | fit 10-3000 | 100->1000 | 1000->3000 |")
print("|---|---|---|---|---|---|---|")
for (motion, density), r in rows.items():
    n = np.array([x[0] for x in r], float)
    for j, name in ((1, "current cull"), (2, "prototype")):
        t = np.array([x[j] for x in r])
        fit = lambda m, n=n, t=t: np.polyfit(np.log(n[m]), np.log(t[m]), 1)[0]  # noqa: E731
        loc = lambda a, b, n=n, t=t: np.log(t[n == b][0] / t[n == a][0]) / np.log(b / a)  # noqa: E731
        print(f"| {motion} | {density} | {name} | {fit(n <= 1000):.2f} | {fit(n <= 3000):.2f} | "
              f"{loc(100, 1000):.2f} | {loc(1000, 3000):.2f} |")
