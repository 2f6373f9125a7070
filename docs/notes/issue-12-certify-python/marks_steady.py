import collections
import sys
import time

import numpy as np

import monitor.certify.engine as E
from monitor.bench.cases import make_cases
from monitor.certify.common import Budget
from monitor.certify.engine import certify

cases = {c.name: c for c in make_cases(seed=7, quick=True)}
for nm in sys.argv[1:] or ["rot-hull-box-near-1e-02", "rot-hull-box-collide", "tra-box-box-clear"]:
    c = cases[nm]
    s, m = c.scene(16), c.body_motion()
    certify(s, m, margin=0.0, epsilon=1e-3, method="toleranced", budget=Budget(seconds=1.0))
    acc = collections.defaultdict(list)
    tot = []
    for _ in range(3000):
        b = Budget(seconds=1.0)
        E._MK.clear()
        t = time.perf_counter()
        certify(s, m, margin=0.0, epsilon=1e-3, method="toleranced", budget=b)
        t1 = time.perf_counter()
        mk = E._MK + [("end", t1)]
        prev = mk[0][1]
        for tag, tt in mk[1:]:
            acc[tag].append(tt - prev)
            prev = tt
        acc["c0"].append(mk[0][1] - t)
        tot.append(t1 - t)
    print(nm, f"total {1e6 * np.median(tot):.1f}")
    for k, v in acc.items():
        print(f"   {k:14s} {1e6 * np.median(v):6.2f}")
