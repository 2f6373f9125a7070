import sys; sys.path.insert(0, "/work/wt/rt12/tests")
import numpy as np, monitor
from monitor.certify import engine
import test_redteam_12 as T
orig = engine._kernel_decided
def key(c):
    w = c.witness
    return (str(c.verdict), c.clearance, c.earliest_time, None if w is None else (w.time, w.geoms, w.distance),
            tuple((p.geoms, str(p.verdict), p.method, p.clearance, p.tests, p.note) for p in c.pairs), c.stats.get("checker_mix"))
n = 0; diffs = 0
for gap in (-0.001, 0.0005, 0.002):
    for alt in (False, True):
        for ongoing in ("violation", "deepen"):
            for margin in (0.0, 0.001):
                m, times, q, pairs = T._hand(8, 0.3, gap, alt)
                plan = monitor.Plan(times, q, m)
                res = []
                for dis in (False, True):
                    engine._kernel_decided = (lambda *a, **k: None) if dis else orig
                    c = monitor.certify(monitor.Scene.from_model(m, pairs=pairs), plan, margin=margin, epsilon=1e-4,
                                        method="toleranced", ongoing=ongoing)
                    res.append(key(c))
                n += 1
                if res[0] != res[1]:
                    diffs += 1; print("DIFF", gap, alt, ongoing, margin, res[0][:3], res[1][:3])
                else:
                    print(gap, alt, ongoing, margin, res[0][0], res[0][5])
print(n, "diffs", diffs)
