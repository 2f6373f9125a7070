"""Same-process A/B of engine._window_kernel's direct entry-point call (on) vs the dispatcher always (off).

Usage: PYTHONPATH=<tree> python direct_ab.py [cases...]; CPU time per certify call, median of 15
blocks of 200 calls, blocks alternated; the certificates of both must be identical.
"""
import sys
import time

import numpy as np

import monitor  # noqa: F401
import monitor.certify.engine as E
from monitor.bench.cases import make_cases
from monitor.certify.common import Budget

names = sys.argv[1:] or ["rot-hull-box-collide", "tra-box-box-graze-1e-03", "rot-box-box-near-1e-02",
                         "tra-box-box-clear"]
cases = {c.name: c for c in make_cases(seed=7, quick=True)}


def key(c):
    w = c.witness
    return (c.verdict, c.earliest_time, c.clearance, c.stats["tests"], repr(c.stats["checker_mix"]),
            None if w is None else (w.time, tuple(w.point), w.distance), repr(c.pairs))


for nm in names:
    c = cases[nm]
    s, m = c.scene(16), c.body_motion()
    res = {"on": [], "off": []}
    certs = {}
    for _ in range(15):
        for lab in ("on", "off"):
            t = time.process_time()
            for _ in range(200):
                if lab == "off":
                    E._WK_DIRECT[0] = None
                cert = E.certify(s, m, margin=0.0, epsilon=1e-3, method="toleranced", budget=Budget(seconds=1.0))
            res[lab].append((time.process_time() - t) / 200)
            certs[lab] = cert
    print(f"{nm:28s} on {1e6 * np.median(res['on']):7.1f} us  off {1e6 * np.median(res['off']):7.1f} us  "
          f"same={key(certs['on']) == key(certs['off'])}")
