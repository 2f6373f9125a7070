"""The bench row's measure (run_ours: fresh scene + motion, 3 timed calls, median) A/B in one process:
base engine.py (7c14058) loaded as a second module; engines alternate per case and round.
"""

import importlib.util
import sys
import time

import numpy as np

import monitor.certify.engine as NEW
from monitor.bench.cases import make_cases
from monitor.certify.common import Budget

spec = importlib.util.spec_from_file_location(
    "monitor.certify._engine_base", "/tmp/certpy/base/monitor/certify/engine.py"
)
OLD = importlib.util.module_from_spec(spec)
sys.modules[spec.name] = OLD
spec.loader.exec_module(OLD)
cases = make_cases(seed=7, quick=True)
rounds = int(sys.argv[1]) if len(sys.argv) > 1 else 5
R = {"base": {}, "new": {}}


def run(E, c):
    s, m = c.scene(16), c.body_motion()
    ts = []
    for _ in range(3):
        b = Budget(seconds=1.0)
        t = time.perf_counter()
        E.certify(s, m, margin=0.0, epsilon=1e-3, method="toleranced", budget=b)
        ts.append(time.perf_counter() - t)
    return 1e6 * float(np.median(ts))


for c in cases:  # warm both (compile, first packs)
    run(OLD, c)
    run(NEW, c)
for r in range(rounds):
    for c in cases:
        order = (("base", OLD), ("new", NEW)) if (r + hash(c.name)) % 2 else (("new", NEW), ("base", OLD))
        for k, E in order:
            R[k].setdefault(c.name, []).append(run(E, c))
med = {k: {n: float(np.median(v)) for n, v in d.items()} for k, d in R.items()}
for k in ("base", "new"):
    print(k, f"median over cases of per-case medians: {np.median(list(med[k].values())):.1f} us")
diffs = [med["base"][n] - med["new"][n] for n in med["base"]]
ratios = [med["new"][n] / med["base"][n] for n in med["base"]]
print(f"per-case base-new: median {np.median(diffs):.1f} us; new/base median {np.median(ratios):.3f}")
for n in med["base"]:
    if med["base"][n] < 1000:
        print(f"  {n:30s} {med['base'][n]:7.1f} {med['new'][n]:7.1f}")
