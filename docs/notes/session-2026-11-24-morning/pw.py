import time, cProfile, pstats, sys
import numpy as np
import monitor
from monitor.bench.cases import make_cases
from monitor.certify.engine import certify
cases = make_cases(seed=7, quick=True)
rot = [c for c in cases if c.group == "rotating"]
print(len(cases), len(rot))
items = [(c.scene(16), c.body_motion()) for c in rot]
for s, m in items:
    certify(s, m, margin=0.0, epsilon=1e-3, method="toleranced")
ts = []
for s, m in items:
    t = time.perf_counter()
    for _ in range(5):
        c = certify(s, m, margin=0.0, epsilon=1e-3, method="toleranced")
    ts.append((time.perf_counter() - t) / 5)
    print(f"{1e6*ts[-1]:9.0f} us {c.verdict:10s} {c.stats['checker_mix']}")
print("median us", 1e6 * np.median(ts))
pr = cProfile.Profile(); pr.enable()
for s, m in items:
    for _ in range(5):
        certify(s, m, margin=0.0, epsilon=1e-3, method="toleranced")
pr.disable()
pstats.Stats(pr).sort_stats("cumulative").print_stats(40)
