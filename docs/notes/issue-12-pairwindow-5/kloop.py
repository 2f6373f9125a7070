"""Replays the recorded stage-0 window_kernel call of bench cases in an njit loop (for perf / timing).

Usage: PYTHONPATH=<tree> python kloop.py SECONDS [case names...]
Prints the CPU time per kernel call of each case (median of batches of 100 calls).
"""
import os
import sys
import time

import numpy as np
from numba import njit

import monitor.certify.engine as E
import monitor.certify.kernels as K
from monitor.bench.cases import make_cases
from monitor.certify.common import Budget
from monitor.certify.engine import certify

secs = float(sys.argv[1])
names = sys.argv[2:] or ["rot-hull-box-near-1e-02", "tra-box-box-graze-1e-03", "rot-hull-box-collide"]
cases = {c.name: c for c in make_cases(seed=7, quick=True)}
rec = []
orig = E._window_kernel


def wk(*a):
    """Records the arguments of the stage-0 window_kernel call."""
    if a[7] == 0:
        rec.append([x.copy() if isinstance(x, np.ndarray) else x for x in a])
    return orig(*a)


wkk = K.window_kernel


@njit
def drive(n, gp, mp, pairs, fixed, moving, route, stage, k0, k1, prm, code, gap, surv, res, sc, sr, info):
    """Calls window_kernel n times with the recorded arguments."""
    for _ in range(n):
        wkk(gp, mp, pairs, fixed, moving, route, stage, k0, k1, prm, code, gap, surv, res, sc, sr, info)


args = []
for nm in names:
    c = cases[nm]
    s, m = c.scene(16), c.body_motion()
    certify(s, m, margin=0.0, epsilon=1e-3, method="toleranced")
    rec.clear()
    E._window_kernel = wk
    certify(s, m, margin=0.0, epsilon=1e-3, method="toleranced", budget=Budget(seconds=1.0))
    E._window_kernel = orig
    args.append((nm, rec[0][1:]))
    drive(1, *rec[0][1:])
if os.environ.get("PERF_MAP"):
    # a perf map of the window kernel's linked machine code (perf finds JIT symbols in /tmp/perf-PID.map)
    lib = next(iter(wkk.overloads.values())).library
    addr = []
    for f in lib._final_module.functions:
        if not f.is_declaration:
            a = lib.get_pointer_to_function(f.name)
            if a:
                addr.append((a, f.name))
    addr.sort()
    with open(f"/tmp/perf-{os.getpid()}.map", "w") as fh:
        for (a, n), nxt in zip(addr, addr[1:] + [(addr[-1][0] + 4096, "")]):
            fh.write(f"{a:x} {nxt[0] - a:x} {n}\n")
t_end = time.time() + secs
per = {nm: [] for nm, _ in args}
while time.time() < t_end:
    for nm, a in args:
        t = time.process_time()
        drive(100, *a)
        per[nm].append((time.process_time() - t) / 100)
for nm, v in per.items():
    print(f"{nm:28s} kernel CPU {1e6 * np.median(v):7.1f} us/call  ({len(v)} batches)")
