"""Cost of the motion-bound pieces on one bench case (issue 12, h12x): njit loops, min of 7 runs, CPU time (process_time: load-independent).

Usage: PYTHONPATH=$PWD python docs/notes/issue-12-kernel-cost/motion_parts.py [case]
"""
import sys
import time

import numpy as np
from numba import njit

import monitor.certify.kernels as K
from monitor.bench.cases import make_cases
from monitor.motion.kernel import (_bounds_core, _fk, _locate, _qpos_at, bounds_workspace, pair_bound,
                                   pair_workspace, tree_bounds)

name = sys.argv[1] if len(sys.argv) > 1 else "rot-hull-box-collide"
c = {c.name: c for c in make_cases(seed=7, quick=True)}[name]
mp = K.trajectory_pack(c.body_motion())
t0, t1 = float(mp.times[0]), float(mp.times[-1])


@njit
def d_tree(n, mp, t0, t1):
    nb = mp.body_parent.shape[0]
    p = np.empty((nb, 3))
    R = np.empty((nb, 3, 3))
    tr = np.empty(nb)
    an = np.empty(nb)
    for i in range(n):
        tree_bounds(mp, t0, t1 - 1e-9 * (i % 7), p, R, tr, an)


@njit
def d_core(n, mp, t0, t1):
    nb = mp.body_parent.shape[0]
    p = np.empty((nb, 3))
    R = np.empty((nb, 3, 3))
    tr = np.empty(nb)
    an = np.empty(nb)
    ws = bounds_workspace(mp)
    need = np.ones(nb, np.int64)
    for i in range(n):
        _bounds_core(mp, t0, t1 - 1e-9 * (i % 7), need, p, R, tr, an, ws)


@njit
def d_pair(n, mp, t0, t1):
    pws = pair_workspace(mp)
    pA = np.empty(3)
    pB = np.empty(3)
    RA = np.empty((3, 3))
    RB = np.empty((3, 3))
    acc = 0.0
    for i in range(n):
        a, b, c, d = pair_bound(mp, 1, 2, t0, t1 - 1e-9 * (i % 7), pA, RA, pB, RB, pws)
        acc += a
    return acc


@njit
def d_fk(n, mp, t0, t1):
    nb = mp.body_parent.shape[0]
    njnt = mp.jnt_type.shape[0]
    ws = bounds_workspace(mp)
    qm, xquat, janchor, jaxis, jframe = ws[0], ws[1], ws[2], ws[3], ws[4]
    need = np.ones(nb, np.int64)
    xpos = np.empty((nb, 3))
    xmat = np.empty((nb, 3, 3))
    for i in range(n):
        lm = _locate(mp.times, 0.5 * (t0 + t1) - 1e-9 * (i % 7))
        _qpos_at(mp.qpos, mp.qt_adr, mp.qt_same, mp.qt_half, mp.qt_target, lm[0], lm[1], lm[2], qm)
        _fk(mp.body_parent, mp.body_mocap, mp.body_pos, mp.body_quat, mp.body_jntadr, mp.body_jntnum, mp.jnt_type,
            mp.jnt_qposadr, mp.jnt_pos, mp.jnt_axis, mp.jnt_axis_norm, mp.qpos0,
            qm, need, xpos, xquat, xmat, janchor, jaxis, jframe, ws[11], ws[12])
    return njnt


def tm(f, n):
    f(1, mp, t0, t1)
    r = []
    for _ in range(7):
        t = time.process_time()
        f(n, mp, t0, t1)
        r.append((time.process_time() - t) / n)
    return 1e6 * min(r)


print(name, "nbody", mp.body_parent.shape[0], "njnt", mp.jnt_type.shape[0], "K", mp.times.shape[0])
for f in (d_tree, d_core, d_pair, d_fk):
    print(f"{f.__name__:8s} {tm(f, 20000):7.3f} us")
