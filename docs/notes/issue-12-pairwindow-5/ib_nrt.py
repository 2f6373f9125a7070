"""What numba's reference counting costs in the per-test functions of kernels.py (a measurement only).

Usage: PYTHONPATH=<tree> python ib_nrt.py [case name]
CPU time per call (best of 7 batches, njit loop over 64 sub-intervals) of interval_bound and of
separated_beyond / posed_distance at the sub-interval midpoints, each as compiled in the tree and as a
copy of its source compiled with ``_nrt=False`` (same arithmetic). The copies are not used anywhere else.
"""
import inspect
import sys
import time

import numpy as np
from numba import njit

import monitor  # noqa: F401
import monitor.certify.kernels as K
import monitor.geometry._gjk as G
from monitor.bench.cases import make_cases
from monitor.motion.kernel import pair_workspace


def _nonrt_copy(fn, module, name):
    src = inspect.getsource(fn.py_func)
    body = src[src.index("def "):]
    ns = dict(module.__dict__)
    exec(body.replace(f"def {fn.py_func.__name__}(", f"def {name}("), ns)
    return njit(no_cpython_wrapper=True, no_cfunc_wrapper=True, _nrt=False)(ns[name])


ib_nonrt = _nonrt_copy(K.interval_bound, K, "ib_nonrt")
sb_nonrt = _nonrt_copy(G.separated_beyond, G, "sb_nonrt") if hasattr(G, "separated_beyond") else None
if sb_nonrt is None:
    sb_nonrt = _nonrt_copy(K.separated_beyond, K, "sb_nonrt")
sb = G.separated_beyond if hasattr(G, "separated_beyond") else K.separated_beyond


@njit
def drive(n, what, gp, mp, ga, gb, t0, t1, rel_pad):
    """Calls variant ``what`` n x 64 times (see ``labels``)."""
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
    VA = np.empty((max(gp.vstart[ga + 1] - gp.vstart[ga], 1), 3))
    VB = np.empty((max(gp.vstart[gb + 1] - gp.vstart[gb], 1), 3))
    W4 = np.zeros((4, 3))
    IA = np.zeros(4, np.int64)
    IB = np.zeros(4, np.int64)
    lam = np.zeros(4)
    v = np.empty(3)
    vn = np.empty(3)
    X = np.empty((5, 3))
    rsum = gp.radius[ga] + gp.radius[gb]
    K.body_pose(mp, gp.body[ga], t0, pA, RA)
    K.body_pose(mp, gp.body[gb], t0, pB, RB)
    acc = 0.0
    for _ in range(n):
        for j in range(64):
            a = t0 + (t1 - t0) * j / 64.0
            b = a + (t1 - t0) / 64.0
            if what == 0:
                acc += K.interval_bound(gp, mp, ga, gb, a, b, pA, RA, pB, RB, levers, stats, rel_pad, pws,
                                        dref)
            elif what == 1:
                acc += ib_nonrt(gp, mp, ga, gb, a, b, pA, RA, pB, RB, levers, stats, rel_pad, pws, dref)
            elif what == 2 or what == 3:
                bound = K.interval_bound(gp, mp, ga, gb, a, b, pA, RA, pB, RB, levers, stats, rel_pad, pws,
                                         dref)
                target = rsum + bound
                X[4, 2] = 0.0
                if what == 2:
                    acc += sb(gp, ga, RA, pA, gb, RB, pB, target * 1.5, target, rel_pad, 0.0, VA, VB, W4,
                              IA, IB, lam, v, vn, X)
                else:
                    acc += sb_nonrt(gp, ga, RA, pA, gb, RB, pB, target * 1.5, target, rel_pad, 0.0, VA, VB,
                                    W4, IA, IB, lam, v, vn, X)
    return acc


nm = sys.argv[1] if len(sys.argv) > 1 else "rot-hull-box-near-1e-02"
c = {c.name: c for c in make_cases(seed=7, quick=True)}[nm]
s, m = c.scene(16), c.body_motion()
gp = K.scene_pack(s).geoms
mp = K.trajectory_pack(m)
t0, t1 = float(mp.times[0]), float(mp.times[-1])
labels = ["interval_bound", "interval_bound copy, _nrt=False", "interval_bound + separated_beyond",
          "interval_bound + separated_beyond copy, _nrt=False"]
print(nm)
for what in range(4):
    drive(1, what, gp, mp, 0, 1, t0, t1, 1e-15)
    best = np.inf
    for _ in range(7):
        t = time.process_time()
        drive(100, what, gp, mp, 0, 1, t0, t1, 1e-15)
        best = min(best, (time.process_time() - t) / (100 * 64))
    print(f"  {labels[what]:52s} {1e9 * best:8.0f} ns/call")
