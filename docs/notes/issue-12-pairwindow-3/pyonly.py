import time, sys
import numpy as np
from monitor.bench.cases import make_cases
from monitor.certify.common import Budget
from monitor.certify.engine import certify
import monitor.certify.engine as E
names = sys.argv[1:] or ["rot-hull-box-near-1e-02", "tra-box-box-clear"]
cases = {c.name: c for c in make_cases(seed=7, quick=True)}
orig = E._window_kernel
for nm in names:
    c = cases[nm]; s, m = c.scene(16), c.body_motion()
    certify(s, m, margin=0.0, epsilon=1e-3, method="toleranced")
    outs = []
    def rec(*a):
        r = orig(*a); outs.append((r, [x.copy() for x in a[11:18]])); return r
    E._window_kernel = rec
    certify(s, m, margin=0.0, epsilon=1e-3, method="toleranced")
    r0, arrs = outs[0]
    def stub(*a):
        for dst, src in zip(a[11:18], arrs):
            dst[...] = src
        return r0
    R = {"real": [], "stub": []}
    for rep in range(15):
        for k, f in (("real", orig), ("stub", stub)):
            E._window_kernel = f
            t = time.process_time()
            for _ in range(200):
                certify(s, m, margin=0.0, epsilon=1e-3, method="toleranced", budget=Budget(seconds=1.0))
            R[k].append((time.process_time() - t) / 200)
    E._window_kernel = orig
    print(f"{nm:28s} " + "  ".join(f"{k} {1e6*np.median(v):7.1f}" for k, v in R.items()), flush=True)
