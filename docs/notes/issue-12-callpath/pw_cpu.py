import time, sys, cProfile, pstats
import numpy as np
from monitor.bench.cases import make_cases
from monitor.certify.engine import certify
from monitor.certify import kernels as KS
cases = make_cases(seed=7, quick=True)
rot = [c for c in cases if c.group == "rotating"]
items = [(c.scene(16), c.body_motion()) for c in rot]
for s, m in items: certify(s, m, margin=0.0, epsilon=1e-3, method="toleranced")
ok = {"toleranced/whole-shape", "static", "culled"}
fast = [(s, m) for s, m in items if set(certify(s, m, margin=0.0, epsilon=1e-3, method="toleranced").stats["checker_mix"]) <= ok]
print(len(items), "cases,", len(fast), "decided by the compiled window")
acc = [0.0]
wk = KS.window_kernel
def timed(*args):
    t = time.process_time(); r = wk(*args); acc[0] += time.process_time() - t; return r
KS.window_kernel = timed
ts, py = [], []
for s, m in items:
    acc[0] = 0.0
    t = time.process_time()
    for _ in range(20): c = certify(s, m, margin=0.0, epsilon=1e-3, method="toleranced")
    ts.append((time.process_time() - t) / 20); py.append(ts[-1] - acc[0] / 20)
print("median us %.0f  (python around the kernel: median %.0f us)" % (1e6 * np.median(ts), 1e6 * np.median(py)))
fi = [k for k, (s, m) in enumerate(items) if any(s is f[0] for f in fast)]
print("compiled-window cases: median %.0f us, python around the kernel median %.0f us" % (1e6 * np.median([ts[k] for k in fi]), 1e6 * np.median([py[k] for k in fi])))
if len(sys.argv) > 1:
    KS.window_kernel = wk
    pr = cProfile.Profile(timer=time.process_time); pr.enable()
    for s, m in fast:
        for _ in range(200): certify(s, m, margin=0.0, epsilon=1e-3, method="toleranced")
    pr.disable(); pstats.Stats(pr).sort_stats("tottime").print_stats(int(sys.argv[1]))
