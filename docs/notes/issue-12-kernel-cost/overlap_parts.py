"""Cost of the exact distance at a colliding pose (issue 12, h12x): posed_distance and its overlap parts.

Usage: PYTHONPATH=$PWD python docs/notes/issue-12-kernel-cost/overlap_parts.py [case]
Poses the pair at the witness time of the case's certificate; CPU time per call (min of 7 x 5000).
"""
import sys
import time

import numpy as np
from numba import njit

import monitor.certify.kernels as K
from monitor.bench.cases import make_cases
from monitor.certify.engine import certify
from monitor.certify.packed import pack_scene
from monitor.geometry._gjk import OUT_SIZE, _epa_inradius, _sat_lower, _tetra_inradius, pose_relative
from monitor.motion.kernel import body_pose

name = sys.argv[1] if len(sys.argv) > 1 else "rot-hull-box-collide"
c = {c.name: c for c in make_cases(seed=7, quick=True)}[name]
s, m = c.scene(16), c.body_motion()
cert = certify(s, m, margin=0.0, epsilon=1e-3, method="toleranced")
tw = float(cert.pairs[0].witness.time)
gp = pack_scene(s).geoms
mp = K.trajectory_pack(m)
ga, gb = int(s.pair_ids[0, 0]), int(s.pair_ids[0, 1])


@njit
def d_pd(n, gp, mp, ga, gb, t):
    pA, pB, RA, RB = np.empty(3), np.empty(3), np.empty((3, 3)), np.empty((3, 3))
    body_pose(mp, gp.body[ga], t, pA, RA)
    body_pose(mp, gp.body[gb], t, pB, RB)
    out = np.empty(OUT_SIZE)
    w = np.empty(3)
    acc = 0.0
    for _ in range(n):
        lo, up = K.posed_distance(gp, ga, RA, pA, gb, RB, pB, 1e-15, 1e-15, out, w)
        acc += up
    return acc, out[0], out[11], lo, up


def tm(f, *a):
    f(1, *a)
    r = []
    for _ in range(7):
        t = time.process_time()
        f(5000, *a)
        r.append((time.process_time() - t) / 5000)
    return 1e6 * min(r)


print(name, "witness t", tw, d_pd(1, gp, mp, ga, gb, tw))
print(f"posed_distance at the witness pose {tm(d_pd, gp, mp, ga, gb, tw):.2f} us;"
      f" at t0 {tm(d_pd, gp, mp, ga, gb, float(mp.times[0])):.2f} us")
