"""Per-stage cost inside window_kernel (issue 12, h12x): njit drivers that loop each stage N times.

Usage: PYTHONPATH=$PWD python docs/notes/issue-12-kernel-cost/stages.py [case names...]
Records the stage-0 window_kernel call of each case (monitor.certify, method toleranced), then times
(min of 5 runs of N in-kernel repetitions, dispatch amortised):
  wk      window_kernel as the engine calls it (stage 0 + first chunk)
  bp      window_kernel stage 0 with k1 = 0 (broad phase only)
  tb      T x tree_bounds alone
  pw0     pair_window setup only (max_tests = 0, start pose known)
  ib      one interval_bound on the whole window
  sb      one separated_beyond at the start pose (target = 0: GJK to convergence)
  pd      one posed_distance at the start pose
"""
import sys
import time

import numpy as np
from numba import njit

import monitor.certify.kernels as K
from monitor.bench.cases import make_cases
from monitor.certify.engine import certify
from monitor.geometry._gjk import OUT_SIZE
from monitor.motion.kernel import body_pose, pair_workspace, tree_bounds

names = sys.argv[1:] or ["tra-box-box-clear", "tra-capsule-box-clear", "tra-box-box-near-1e-02",
                         "rot-hull-box-collide", "tra-box-box-graze-1e-03"]
cases = {c.name: c for c in make_cases(seed=7, quick=True)}
rec = []
orig = K.window_kernel


class W:
    def __getattr__(self, a):
        return getattr(orig, a)

    def __call__(self, *a):
        if a[6] == 0:
            rec.append([x.copy() if isinstance(x, np.ndarray) else x for x in a])
        return orig(*a)


import monitor.certify.engine as E  # noqa: E402
K.window_kernel = W()


@njit
def d_wk(n, gp, mp, pairs, fixed, moving, route, stage, k0, k1, prm, code, gap, surv, res, sc, sr, info):
    for _ in range(n):
        orig(gp, mp, pairs, fixed, moving, route, stage, k0, k1, prm, code, gap, surv, res, sc, sr, info)


@njit
def d_tb(n, mp, T, t0, t1):
    nbody = mp.body_parent.shape[0]
    pos = np.empty((T, nbody, 3))
    rot = np.empty((T, nbody, 3, 3))
    trans = np.empty((T, nbody))
    ang = np.empty((T, nbody))
    for _ in range(n):
        step = (t1 - t0) / T
        for t in range(T):
            tree_bounds(mp, t * step + t0, t1 if t == T - 1 else (t + 1) * step + t0, pos[t], rot[t], trans[t],
                        ang[t])


@njit
def d_pw0(n, gp, mp, ga, gb, t0, t1, prm):
    stack = np.empty((int(prm[K.WP_MAX_DEPTH]) + 2, 3))
    row = np.zeros(K.R_SIZE)
    for _ in range(n):
        row[K.R_STARTED] = 2.0
        row[K.R_SP] = 0.0
        K.pair_window(gp, mp, ga, gb, t0, t1, 0.0, 1e-3, 40, 0, K.MODE_CERTIFY_ONLY, prm[K.WP_REL],
                      prm[K.WP_ABS], stack, row)


@njit
def d_ib(n, gp, mp, ga, gb, t0, t1, prm):
    pws = pair_workspace(mp)
    pA = np.empty(3)
    pB = np.empty(3)
    RA = np.empty((3, 3))
    RB = np.empty((3, 3))
    body_pose(mp, gp.body[ga], t0, pA, RA)
    body_pose(mp, gp.body[gb], t0, pB, RB)
    levers = np.ones(2)
    PvA = gp.verts[gp.vstart[ga]:gp.vstart[ga + 1]]
    PmA = gp.mpts[gp.mstart[ga]:gp.mstart[ga + 1]]
    PvB = gp.verts[gp.vstart[gb]:gp.vstart[gb + 1]]
    PmB = gp.mpts[gp.mstart[gb]:gp.mstart[gb + 1]]
    dref = (np.ones(PvA.shape[0]), np.ones(PmA.shape[0]), np.ones(PvB.shape[0]), np.ones(PmB.shape[0]))
    stats = np.zeros(1)
    acc = 0.0
    for _ in range(n):
        acc += K.interval_bound(gp, mp, ga, gb, t0, t1, pA, RA, pB, RB, levers, stats, prm[K.WP_REL], pws, dref)
    return acc


@njit
def d_sb(n, gp, mp, ga, gb, t0, prm):
    pA = np.empty(3)
    pB = np.empty(3)
    RA = np.empty((3, 3))
    RB = np.empty((3, 3))
    body_pose(mp, gp.body[ga], t0, pA, RA)
    body_pose(mp, gp.body[gb], t0, pB, RB)
    VA = np.empty((max(gp.vstart[ga + 1] - gp.vstart[ga], 1), 3))
    VB = np.empty((max(gp.vstart[gb + 1] - gp.vstart[gb], 1), 3))
    W4 = np.zeros((4, 3))
    IA = np.zeros(4, np.int64)
    IB = np.zeros(4, np.int64)
    lam = np.zeros(4)
    v = np.empty(3)
    vn = np.empty(3)
    X = np.empty((4, 3))
    out = np.empty(OUT_SIZE)
    w = np.empty(3)
    acc = 0.0
    for _ in range(n):
        acc += K.separated_beyond(gp, ga, RA, pA, gb, RB, pB, np.inf, 0.0, prm[K.WP_REL], prm[K.WP_ABS], VA, VB,
                                  W4, IA, IB, lam, v, vn, X)
    t_sb = acc
    acc = 0.0
    return t_sb


@njit
def d_pd(n, gp, mp, ga, gb, t0, prm):
    pA = np.empty(3)
    pB = np.empty(3)
    RA = np.empty((3, 3))
    RB = np.empty((3, 3))
    body_pose(mp, gp.body[ga], t0, pA, RA)
    body_pose(mp, gp.body[gb], t0, pB, RB)
    out = np.empty(OUT_SIZE)
    w = np.empty(3)
    acc = 0.0
    for _ in range(n):
        lo, up = K.posed_distance(gp, ga, RA, pA, gb, RB, pB, prm[K.WP_REL], prm[K.WP_ABS], out, w)
        acc += lo
    return acc


def tm(f, n, *a):
    f(1, *a)
    r = []
    for _ in range(5):
        t = time.perf_counter()
        f(n, *a)
        r.append((time.perf_counter() - t) / n)
    return 1e6 * float(np.min(r))


print(f"{'case':28s} {'tests':>5s} {'wk':>7s} {'bp':>7s} {'tb':>7s} {'pw0':>7s} {'ib':>7s} {'sb':>7s} {'pd':>7s}")
for nm in names:
    c = cases[nm]
    s, m = c.scene(16), c.body_motion()
    rec.clear()
    cert = certify(s, m, margin=0.0, epsilon=1e-3, method="toleranced")
    a = rec[0]
    gp, mp, pairs, prm = a[0], a[1], a[2], a[9]
    t0, t1 = prm[K.WP_T0], prm[K.WP_T1]
    ga, gb = int(pairs[0, 0]), int(pairs[0, 1])
    T = a[14].shape[0]
    wk = tm(d_wk, 200, *a)
    b = list(a)
    b[8] = 0
    bp = tm(d_wk, 200, *b)
    tb = tm(d_tb, 200, mp, T, t0, t1)
    pw0 = tm(d_pw0, 500, gp, mp, ga, gb, t0, t1, prm)
    ib = tm(d_ib, 2000, gp, mp, ga, gb, t0, t1, prm)
    sb = tm(d_sb, 2000, gp, mp, ga, gb, t0, prm)
    pd = tm(d_pd, 2000, gp, mp, ga, gb, t0, prm)
    print(f"{nm:28s} {cert.stats.get('tests', 0):5d} {wk:7.1f} {bp:7.1f} {tb:7.1f} {pw0:7.1f} {ib:7.1f} {sb:7.1f} "
          f"{pd:7.1f}", flush=True)
