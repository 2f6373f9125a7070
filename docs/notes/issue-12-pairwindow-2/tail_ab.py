"""Same-process A/B of engine._kernel_decided (on) vs the general tail (off: patched to return None).

Usage: PYTHONPATH=<tree> python tail_ab.py [cases...]; CPU time per certify call, median of 15 blocks
of 200 calls, blocks alternated on/off.
"""
import sys
import time

import numpy as np

import monitor  # noqa: F401
import monitor.certify.engine as E
from monitor.bench.cases import make_cases
from monitor.certify.common import Budget

names = sys.argv[1:] or ["rot-hull-box-collide", "tra-box-box-graze-1e-03", "rot-box-box-near-1e-02"]
cases = {c.name: c for c in make_cases(seed=7, quick=True)}
on = E._kernel_decided


def off(*a, **k):
    return None


for nm in names:
    c = cases[nm]
    s, m = c.scene(16), c.body_motion()
    res = {"on": [], "off": []}
    certs = {}
    for _ in range(15):
        for lab, f in (("on", on), ("off", off)):
            E._kernel_decided = f
            t = time.process_time()
            for _ in range(200):
                cert = E.certify(s, m, margin=0.0, epsilon=1e-3, method="toleranced", budget=Budget(seconds=1.0))
            res[lab].append((time.process_time() - t) / 200)
            certs[lab] = cert
    E._kernel_decided = on
    a, b = certs["on"], certs["off"]
    same = (a.verdict, a.earliest_time, a.clearance, a.stats["tests"], a.stats["checker_mix"],
            None if a.witness is None else (a.witness.time, tuple(a.witness.point), a.witness.distance)) == \
           (b.verdict, b.earliest_time, b.clearance, b.stats["tests"], b.stats["checker_mix"],
            None if b.witness is None else (b.witness.time, tuple(b.witness.point), b.witness.distance))
    print(f"{nm:28s} on {1e6 * np.median(res['on']):7.1f} us  off {1e6 * np.median(res['off']):7.1f} us  "
          f"same={same} pairs_same={repr(a.pairs) == repr(b.pairs)}")
