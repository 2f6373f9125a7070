"""One process, both engines: base engine.py (7c14058) loaded as a second module, alternated in blocks."""

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
names = sys.argv[1:] or [
    "rot-hull-box-near-1e-02",
    "rot-hull-box-collide",
    "rot-box-box-graze-1e-03",
    "tra-box-box-clear",
    "tra-hull-box-clear",
]
cases = {c.name: c for c in make_cases(seed=7, quick=True)}
for nm in names:
    c = cases[nm]
    s, m = c.scene(16), c.body_motion()
    R = {"base": [], "new": []}
    certs = {}
    for k, E in (("base", OLD), ("new", NEW)):
        certs[k] = E.certify(s, m, margin=0.0, epsilon=1e-3, method="toleranced", budget=Budget(seconds=1.0))
    dd = [certs[k].to_dict() for k in ("base", "new")]
    for d in dd:
        d["stats"].pop("wall_seconds")
    assert dd[0] == dd[1], nm
    for rep in range(21):
        for k, E in (("base", OLD), ("new", NEW)) if rep % 2 else (("new", NEW), ("base", OLD)):
            f = E.certify
            ts = []
            for _ in range(150):
                b = Budget(seconds=1.0)
                t = time.process_time()
                f(s, m, margin=0.0, epsilon=1e-3, method="toleranced", budget=b)
                ts.append(time.process_time() - t)
            R[k].append(np.median(ts))
    b_, n_ = 1e6 * np.median(R["base"]), 1e6 * np.median(R["new"])
    ratio = np.median(np.array(R["new"]) / np.array(R["base"]))
    print(f"{nm:28s} base {b_:7.1f}  new {n_:7.1f}  diff {b_ - n_:5.1f} us  new/base {ratio:.3f}", flush=True)
