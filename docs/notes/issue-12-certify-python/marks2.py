import collections
import time

import numpy as np

import monitor.certify.engine as E
from monitor.bench.cases import make_cases
from monitor.certify.common import Budget
from monitor.certify.engine import certify

cases = [
    c
    for c in make_cases(seed=7, quick=True)
    if c.group in ("rotating", "translating") and "1e-04" not in c.name
]
for c in cases:
    certify(
        c.scene(16),
        c.body_motion(),
        margin=0.0,
        epsilon=1e-3,
        method="toleranced",
        budget=Budget(seconds=1.0),
    )
acc = collections.defaultdict(list)
tot = []
for _r in range(5):
    for c in cases:
        s, m = c.scene(16), c.body_motion()
        for i in range(3):
            b = Budget(seconds=1.0)
            E._MK.clear()
            t = time.perf_counter()
            certify(s, m, margin=0.0, epsilon=1e-3, method="toleranced", budget=b)
            t1 = time.perf_counter()
            if i != 1:
                continue
            mk = E._MK + [("end", t1)]
            prev = mk[0][1]
            for tag, tt in mk[1:]:
                acc[tag].append(tt - prev)
                prev = tt
            tot.append(t1 - t)
print(f"2nd call, total median {1e6 * np.median(tot):.1f}")
for k, v in acc.items():
    print(f"   {k:14s} {1e6 * np.median(v):6.2f}  (n={len(v)})")
