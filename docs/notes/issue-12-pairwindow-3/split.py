import time, sys
import numpy as np
from numba import njit
from monitor.bench.cases import make_cases
from monitor.certify.common import Budget
from monitor.certify.engine import certify
import monitor.certify.engine as E
import monitor.certify.kernels as K
names = sys.argv[1:] or ["rot-hull-box-near-1e-02", "tra-box-box-graze-1e-03", "rot-hull-box-collide", "tra-box-box-clear"]
cases = {c.name: c for c in make_cases(seed=7, quick=True)}
rec = []
orig = E._window_kernel
def wk(*a):
    if a[7] == 0:
        rec.append([x.copy() if isinstance(x, np.ndarray) else x for x in a])
    return orig(*a)
wkk = K.window_kernel
@njit
def drive(n, gp, mp, pairs, fixed, moving, route, stage, k0, k1, prm, code, gap, surv, res, sc, sr, info):
    for _ in range(n):
        wkk(gp, mp, pairs, fixed, moving, route, stage, k0, k1, prm, code, gap, surv, res, sc, sr, info)
for nm in names:
    c = cases[nm]; s, m = c.scene(16), c.body_motion()
    certify(s, m, margin=0.0, epsilon=1e-3, method="toleranced")
    rec.clear(); E._window_kernel = wk
    certify(s, m, margin=0.0, epsilon=1e-3, method="toleranced", budget=Budget(seconds=1.0))
    E._window_kernel = orig
    a = rec[0][1:]
    ep = next(iter(wkk.overloads.values())).entry_point
    drive(1, *a)
    R = {"certify": [], "entry": [], "loop": []}
    for rep in range(15):
        t = time.process_time()
        for _ in range(100):
            certify(s, m, margin=0.0, epsilon=1e-3, method="toleranced", budget=Budget(seconds=1.0))
        R["certify"].append((time.process_time() - t) / 100)
        t = time.process_time()
        for _ in range(100):
            ep(*a)
        R["entry"].append((time.process_time() - t) / 100)
        t = time.process_time()
        drive(100, *a)
        R["loop"].append((time.process_time() - t) / 100)
    print(f"{nm:28s} " + "  ".join(f"{k} {1e6*np.median(v):7.1f}" for k, v in R.items()), flush=True)
