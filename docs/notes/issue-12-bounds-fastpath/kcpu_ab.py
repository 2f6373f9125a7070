"""Kernel CPU per median case: one compiled pairs_window search, CPU, median of 301 calls.

The whole-shape pair-window search (no Python per test) of the cases around the bench's median.

Usage: PYTHONPATH=<tree> python kcpu_ab.py   (run it for two trees alternately; compare in one shell)
"""
import time

import numpy as np

import monitor  # noqa: F401
import monitor.certify.kernels as K
from monitor.bench.cases import make_cases

NAMES = ["rot-hull-box-collide", "tra-box-box-graze-1e-03", "rot-box-box-near-1e-02", "tra-box-box-collide",
         "rot-hull-box-near-1e-02"]
cases = {c.name: c for c in make_cases(seed=7, quick=True)}
for nm in NAMES:
    c = cases[nm]
    s, m = c.scene(16), c.body_motion()
    gp = K.scene_pack(s).geoms
    mp = K.trajectory_pack(m)
    pairs = np.array([[0, 1]], np.int64)
    res = np.zeros((1, K.R_SIZE))
    t0, t1 = float(mp.times[0]), float(mp.times[-1])
    args = (gp, mp, pairs, t0, t1, 0.0, 1e-3, 40, 100000, 0, 64 * 2.0**-52, 1e-12, res)
    K.pairs_window(*args)
    ts = []
    for _ in range(301):
        t = time.process_time()
        K.pairs_window(*args)
        ts.append(time.process_time() - t)
    print(f"{nm:26s} {1e6 * np.median(ts):7.1f} us  verdict {res[0, K.R_VERDICT]:.0f} "
          f"tests {res[0, K.R_TESTS]:.0f} wtime {res[0, K.R_WTIME]!r} clear {res[0, K.R_CLEAR]!r}")
