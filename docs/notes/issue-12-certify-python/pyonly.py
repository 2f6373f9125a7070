import sys
import time

import numpy as np

import monitor.certify.engine as E
from monitor.bench.cases import make_cases
from monitor.certify.common import Budget
from monitor.certify.engine import certify

names = sys.argv[1:] or ["rot-hull-box-near-1e-02", "rot-hull-box-collide", "tra-box-box-clear"]
cases = {c.name: c for c in make_cases(seed=7, quick=True)}
KS = E._kernels()
orig_wk = E._window_kernel
for nm in names:
    c = cases[nm]
    s, m = c.scene(16), c.body_motion()
    certify(s, m, margin=0.0, epsilon=1e-3, method="toleranced")
    outs = []

    def rec(*a):
        r = orig_wk(*a)
        outs.append((r, [x.copy() for x in a[12:19]]))
        return r

    E._window_kernel = rec
    certify(s, m, margin=0.0, epsilon=1e-3, method="toleranced", budget=Budget(seconds=1.0))
    E._window_kernel = orig_wk
    r0, arrs = outs[0]

    def stub(*a):
        for dst, src in zip(a[12:19], arrs):
            dst[...] = src
        return r0

    R = {"real": [], "stub": []}
    for _rep in range(15):
        for k, f in (("real", orig_wk), ("stub", stub)):
            E._window_kernel = f
            tt = 0.0
            for _ in range(200):
                b = Budget(seconds=1.0)
                t = time.process_time()
                certify(s, m, margin=0.0, epsilon=1e-3, method="toleranced", budget=b)
                tt += time.process_time() - t
            R[k].append(tt / 200)
    E._window_kernel = orig_wk
    print(f"{nm:28s} " + "  ".join(f"{k} {1e6 * np.median(v):7.1f}" for k, v in R.items()), flush=True)
