"""One-pair extrusion calls (n-ary + offset pipeline, the engine's configuration): median per pair-window.

Seeded set of issue 14 (`seeded_translating_pairs(11, 80)`), min of 3 reps per pair; verdict counts.
Run from the tree to measure: PYTHONPATH=<tree> python <this file> <tree>/tests
"""
import collections
import sys
import time

import numpy as np

from monitor.certify.extrusion_null import warm_small_lp

warm_small_lp()
sys.path.insert(0, sys.argv[1] if len(sys.argv) > 1 else "tests")
from test_extrusion_pipeline import seeded_translating_pairs  # noqa: E402

from monitor.certify.extrusion import check_pairs  # noqa: E402
from monitor.tolerances import DEFAULT  # noqa: E402

pairs = seeded_translating_pairs(11, 80)
ext = DEFAULT.extrusion_slack + DEFAULT.pad(0.0)
check_pairs(pairs[:3], (0.0, 1.0), ext, nary=True, offset=True)
res = []
verdicts = collections.Counter()
for rep in range(3):
    ts = []
    for p in pairs:
        t = time.perf_counter()
        out = check_pairs([p], (0.0, 1.0), ext, nary=True, offset=True)
        ts.append(time.perf_counter() - t)
        if rep == 0:
            verdicts[str(out[0].verdict)] += 1
    res.append(ts)
m = np.min(np.array(res), axis=0)
print(f"median per pair-window {np.median(m) * 1e3:.3f} ms, p90 {np.quantile(m, 0.9) * 1e3:.3f} ms, {dict(verdicts)}")
