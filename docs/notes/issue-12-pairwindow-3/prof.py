import time, sys
import numpy as np
from monitor.bench.cases import make_cases
from monitor.certify.common import Budget
from monitor.certify.engine import certify
import monitor.certify.engine as E
import monitor.certify.kernels as K
cases = make_cases(seed=7, quick=True)
items = [(c, c.scene(16), c.body_motion()) for c in cases]
for c, s, m in items:
    certify(s, m, margin=0.0, epsilon=1e-3, method="toleranced", budget=Budget(seconds=1.0))
kt = [0.0]
orig = E._window_kernel
def wk(*a):
    t = time.perf_counter(); r = orig(*a); kt[0] += time.perf_counter() - t; return r
E._window_kernel = wk
rows = []
for c, s, m in items:
    n = 31 if "1e-04" not in c.name and c.group in ("rotating", "translating") else 3
    tt, kk = [], []
    for _ in range(n):
        kt[0] = 0.0
        b = Budget(seconds=1.0)
        t = time.perf_counter(); cert = certify(s, m, margin=0.0, epsilon=1e-3, method="toleranced", budget=b); tt.append(time.perf_counter() - t)
        kk.append(kt[0])
    rows.append((np.median(tt), np.median(kk), c.name, c.group, str(cert.verdict), cert.stats.get("checker_mix"), cert.stats.get("tests")))
rows.sort()
for tt, kk, n, g, v, mix, te in rows:
    print(f"{1e6*tt:9.0f} kern {1e6*kk:9.0f} {g:12s} {v:10s} {mix} tests={te} {n}")
print("median", 1e6*np.median([r[0] for r in rows]))
