"""CPU time of window_kernel on the culled cases only (stage 0 = broad phase; issue 12, h12x).

Usage: PYTHONPATH=<tree> python docs/notes/issue-12-kernel-cost/culled_ab.py; run two trees concurrently.
"""
import time

import numpy as np
from numba import njit

import monitor.certify.kernels as K
from monitor.bench.cases import make_cases
from monitor.certify.engine import certify

rec = []
orig = K.window_kernel


class W:
    """Records the stage-0 call's arguments."""

    def __getattr__(self, a):
        return getattr(orig, a)

    def __call__(self, *a):
        if a[6] == 0:
            rec.append([x.copy() if isinstance(x, np.ndarray) else x for x in a])
        return orig(*a)


K.window_kernel = W()


@njit
def drive(n, gp, mp, pairs, fixed, moving, route, stage, k0, k1, prm, code, gap, surv, res, sc, sr, info):
    """n calls in one compiled loop."""
    for _ in range(n):
        orig(gp, mp, pairs, fixed, moving, route, stage, k0, k1, prm, code, gap, surv, res, sc, sr, info)


for c in make_cases(seed=7, quick=True):
    if not c.name.endswith("-clear") or "capsule" in c.name or c.name.startswith("tra-hull"):
        continue
    rec.clear()
    certify(c.scene(16), c.body_motion(), margin=0.0, epsilon=1e-3, method="toleranced")
    a = rec[0]
    drive(10, *a)
    r = []
    for _ in range(15):
        t = time.process_time()
        drive(2000, *a)
        r.append((time.process_time() - t) / 2000)
    print(f"{c.name:24s} {1e6 * min(r):7.2f} us CPU (min of 15 x 2000)", flush=True)
