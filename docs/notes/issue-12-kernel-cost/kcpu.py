"""CPU time (process_time: robust to the shared machine's load) of window_kernel and certify per bench case.

Usage: [NUMBA_CACHE_DIR=...] PYTHONPATH=<tree> python docs/notes/issue-12-kernel-cost/kcpu.py [out.json]
For each of the 36 quick peers cases (seed 7, toleranced, epsilon 1e-3, margin 0): the recorded stage-0
window_kernel call replayed 200 times inside one njit loop (no dispatch; min over 5 runs), and certify
itself (median over 7 calls). Prints per case and the medians; writes JSON for ab comparison.
"""
import json
import sys
import time

import numpy as np
from numba import njit

import monitor.certify.kernels as K
from monitor.bench.cases import make_cases
from monitor.certify.engine import certify

rec = []
orig = K.window_kernel


class W:
    def __getattr__(self, a):
        return getattr(orig, a)

    def __call__(self, *a):
        if a[6] == 0:
            rec.append([x.copy() if isinstance(x, np.ndarray) else x for x in a])
        return orig(*a)


K.window_kernel = W()


@njit
def drive(n, gp, mp, pairs, fixed, moving, route, stage, k0, k1, prm, code, gap, surv, res, sc, sr, info):
    for _ in range(n):
        orig(gp, mp, pairs, fixed, moving, route, stage, k0, k1, prm, code, gap, surv, res, sc, sr, info)


out = {}
for c in make_cases(seed=7, quick=True):
    s, m = c.scene(16), c.body_motion()
    rec.clear()
    cert = certify(s, m, margin=0.0, epsilon=1e-3, method="toleranced")
    kern = np.nan
    if rec:
        a = rec[0]
        drive(1, *a)
        r = []
        for _ in range(5):
            t = time.process_time()
            drive(200, *a)
            r.append((time.process_time() - t) / 200)
        kern = 1e6 * min(r)
    r = []
    for _ in range(7 if c.group in ("translating", "rotating") else 2):
        t = time.process_time()
        cert = certify(s, m, margin=0.0, epsilon=1e-3, method="toleranced")
        r.append(time.process_time() - t)
    tot = 1e6 * float(np.median(r))
    w = cert.pairs[0].witness if cert.pairs and cert.pairs[0].witness is not None else None
    out[c.name] = dict(kern=kern, tot=tot, verdict=str(cert.verdict), tests=int(cert.stats.get("tests", 0)),
                       wtime=None if w is None else float(w.time))
    print(f"{c.name:28s} kern {kern:8.1f} tot {tot:9.1f} {cert.verdict:10s} tests={out[c.name]['tests']}",
          flush=True)
print("median tot", np.median([v["tot"] for v in out.values()]),
      "median kern (fast cases)", np.nanmedian([v["kern"] for v in out.values()]))
if len(sys.argv) > 1:
    json.dump(out, open(sys.argv[1], "w"), indent=1)
