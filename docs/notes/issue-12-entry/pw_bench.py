"""Per-case certify time over the bench's lerp/slerp pair-windows (like /work/wt/prof/pw.py, both groups).

PYTHONPATH=<tree> python pw_bench.py [reps] -> JSON: median over cases of the per-case median µs,
for method "toleranced" (the bench row's checker for rotating cases) and "auto".
Cases are pickled once to $PW_CASES (default /tmp/entry_pw_cases.pkl): make_cases takes ~20 s.
"""
import json
import os
import pickle
import sys
import time

import numpy as np

from monitor.certify.engine import certify

reps = int(sys.argv[1]) if len(sys.argv) > 1 else 20
CACHE = os.environ.get("PW_CASES", "/tmp/entry_pw_cases.pkl")
if os.path.exists(CACHE):
    with open(CACHE, "rb") as f:
        items = pickle.load(f)
else:
    from monitor.bench.cases import make_cases
    items = [(c.name, c.scene(16), c.body_motion()) for c in make_cases(seed=7, quick=True)
             if c.group in ("translating", "rotating")]
    with open(CACHE, "wb") as f:
        pickle.dump(items, f)
out = {}
for method in ("toleranced", "auto"):
    per = []
    for _name, s, m in items:
        certify(s, m, margin=0.0, epsilon=1e-3, method=method)
        ts = []
        for _ in range(reps):
            t = time.perf_counter()
            certify(s, m, margin=0.0, epsilon=1e-3, method=method)
            ts.append(time.perf_counter() - t)
        per.append(np.median(ts))
    out[method] = dict(median_us=float(np.median(per)) * 1e6, cases=len(per))
print(json.dumps(out))
