"""interval_bound vs its pair_bound (motion kernel) per call, CPU time, on the bench cases' pairs.

Usage: PYTHONPATH=<tree> python ib_parts.py [case names...]
Drives both in an njit loop over 64 sub-intervals of the window (no dispatch per call).
"""
import sys
import time

import numpy as np
from numba import njit

import monitor  # noqa: F401
import monitor.certify.kernels as K
from monitor.bench.cases import make_cases
from monitor.motion.kernel import pair_bound, pair_workspace


@njit
def drive_pb(n, mp, ba, bb, t0, t1):
    pws = pair_workspace(mp)
    pA, pB, RA, RB = np.empty(3), np.empty(3), np.empty((3, 3)), np.empty((3, 3))
    acc = 0.0
    for _ in range(n):
        for j in range(64):
            a = t0 + (t1 - t0) * j / 64.0
            b = a + (t1 - t0) / 64.0
            TA, angA, TB, angB = pair_bound(mp, ba, bb, a, b, pA, RA, pB, RB, pws)
            acc += TA + angB
    return acc


@njit
def drive_ib(n, gp, mp, ga, gb, t0, t1, rel_pad):
    pws = pair_workspace(mp)
    pA, pB, RA, RB = np.empty(3), np.empty(3), np.empty((3, 3)), np.empty((3, 3))
    levers = np.zeros(2)
    stats = np.zeros(1)
    refA, refB = mp.ref_points[gp.body[ga]], mp.ref_points[gp.body[gb]]
    PvA = gp.verts[gp.vstart[ga]:gp.vstart[ga + 1]]
    PmA = gp.mpts[gp.mstart[ga]:gp.mstart[ga + 1]]
    PvB = gp.verts[gp.vstart[gb]:gp.vstart[gb + 1]]
    PmB = gp.mpts[gp.mstart[gb]:gp.mstart[gb + 1]]
    dref = (np.empty(PvA.shape[0]), np.empty(PmA.shape[0]), np.empty(PvB.shape[0]), np.empty(PmB.shape[0]))
    levers[0] = K._lever(PvA, refA, dref[0])
    K._lever(PmA, refA, dref[1])
    levers[1] = K._lever(PvB, refB, dref[2])
    K._lever(PmB, refB, dref[3])
    acc = 0.0
    for _ in range(n):
        for j in range(64):
            a = t0 + (t1 - t0) * j / 64.0
            b = a + (t1 - t0) / 64.0
            acc += K.interval_bound(gp, mp, ga, gb, a, b, pA, RA, pB, RB, levers, stats, rel_pad, pws, dref)
    return acc


names = sys.argv[1:] or ["rot-box-box-near-1e-02", "tra-box-box-graze-1e-03", "rot-hull-box-collide"]
cases = {c.name: c for c in make_cases(seed=7, quick=True)}
for nm in names:
    c = cases[nm]
    s, m = c.scene(16), c.body_motion()
    gp = K.scene_pack(s).geoms
    mp = K.trajectory_pack(m)
    ga, gb = 0, 1
    ba, bb = int(gp.body[ga]), int(gp.body[gb])
    ba = ba if mp.body_moving[ba] else -1
    bb = bb if mp.body_moving[bb] else -1
    t0, t1 = float(mp.times[0]), float(mp.times[-1])
    drive_pb(1, mp, ba, bb, t0, t1)
    drive_ib(1, gp, mp, ga, gb, t0, t1, 1e-15)
    best = [np.inf, np.inf]
    for _ in range(7):
        t = time.process_time()
        drive_pb(200, mp, ba, bb, t0, t1)
        best[0] = min(best[0], (time.process_time() - t) / (200 * 64))
        t = time.process_time()
        drive_ib(200, gp, mp, ga, gb, t0, t1, 1e-15)
        best[1] = min(best[1], (time.process_time() - t) / (200 * 64))
    print(f"{nm:28s} nbody {mp.body_parent.shape[0]} K {mp.times.shape[0]}: pair_bound {1e6 * best[0]:.2f} us, "
          f"interval_bound {1e6 * best[1]:.2f} us per call (CPU, best of 7)")
