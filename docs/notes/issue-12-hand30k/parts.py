"""Per-survivor component costs (njit drivers around the kernel's own functions), hand30 joint windows."""
import sys, time
import numpy as np
from numba import njit
import h30
import monitor.certify.engine as E
import monitor.certify.kernels as KS
from monitor.motion.kernel import body_pose, pair_workspace
from monitor.certify.kernels import posed_distance, interval_bound, separated_beyond, _lever, OUT_SIZE

@njit
def d_start(gp, mp, pairs, sv, t0, reps, rel, ab):
    out = np.empty(OUT_SIZE); w = np.empty(3); pA = np.empty(3); pB = np.empty(3)
    RA = np.empty((3, 3)); RB = np.empty((3, 3)); acc = 0.0
    for r in range(reps):
        for k in sv:
            ga, gb = pairs[k, 0], pairs[k, 1]
            body_pose(mp, gp.body[ga], t0, pA, RA)
            body_pose(mp, gp.body[gb], t0, pB, RB)
            lo, up = posed_distance(gp, ga, RA, pA, gb, RB, pB, rel, ab, out, w)
            acc += lo
    return acc

@njit
def d_pose(gp, mp, pairs, sv, t0, reps):
    pA = np.empty(3); pB = np.empty(3); RA = np.empty((3, 3)); RB = np.empty((3, 3)); acc = 0.0
    for r in range(reps):
        for k in sv:
            ga, gb = pairs[k, 0], pairs[k, 1]
            body_pose(mp, gp.body[ga], t0, pA, RA)
            body_pose(mp, gp.body[gb], t0, pB, RB)
            acc += pA[0]
    return acc

@njit
def d_bound(gp, mp, pairs, sv, t0, t1, reps, rel):
    pA = np.empty(3); pB = np.empty(3); RA = np.empty((3, 3)); RB = np.empty((3, 3)); acc = 0.0
    pws = pair_workspace(mp); stats = np.zeros(1); levers = np.zeros(2)
    for r in range(reps):
        for k in sv:
            ga, gb = pairs[k, 0], pairs[k, 1]
            PvA = gp.verts[gp.vstart[ga]:gp.vstart[ga + 1]]
            PmA = gp.mpts[gp.mstart[ga]:gp.mstart[ga + 1]]
            PvB = gp.verts[gp.vstart[gb]:gp.vstart[gb + 1]]
            PmB = gp.mpts[gp.mstart[gb]:gp.mstart[gb + 1]]
            refA, refB = mp.ref_points[gp.body[ga]], mp.ref_points[gp.body[gb]]
            dref = (np.empty(PvA.shape[0]), np.empty(PmA.shape[0]), np.empty(PvB.shape[0]), np.empty(PmB.shape[0]))
            levers[0] = _lever(PvA, refA, dref[0]); _lever(PmA, refA, dref[1])
            levers[1] = _lever(PvB, refB, dref[2]); _lever(PmB, refB, dref[3])
            acc += interval_bound(gp, mp, ga, gb, t0, t1, pA, RA, pB, RB, levers, stats, rel, pws, dref)
    return acc

@njit
def d_gjk(gp, mp, pairs, sv, t0, t1, reps, rel, ab):
    pA = np.empty(3); pB = np.empty(3); RA = np.empty((3, 3)); RB = np.empty((3, 3)); acc = 0.0
    tm = 0.5 * (t0 + t1)
    X = np.empty((5, 3)); W4 = np.zeros((4, 3)); IA = np.zeros(4, np.int64); IB = np.zeros(4, np.int64)
    lam = np.zeros(4); v = np.empty(3); vn = np.empty(3)
    for r in range(reps):
        for k in sv:
            ga, gb = pairs[k, 0], pairs[k, 1]
            body_pose(mp, gp.body[ga], tm, pA, RA)
            body_pose(mp, gp.body[gb], tm, pB, RB)
            VA = np.empty((max(gp.vstart[ga + 1] - gp.vstart[ga], 1), 3))
            VB = np.empty((max(gp.vstart[gb + 1] - gp.vstart[gb], 1), 3))
            X[4, 2] = 0.0
            acc += separated_beyond(gp, ga, RA, pA, gb, RB, pB, 0.0, 0.0, rel, ab, VA, VB, W4, IA, IB, lam, v, vn, X)
    return acc

kept, W, scene, req = h30.setup(sys.argv[1])
rec, _wk = h30.spy_kernel_calls()
pc = time.thread_time   # CPU time of this thread: robust to the shared machine's time-sharing
res = {k: [] for k in ("start", "pose", "bound", "gjk")}
nsurv = []
for i in range(0, len(kept), 6):
    p = h30.joint_plan(W, kept[i])
    rec.clear(); E.certify(scene, p, request=req)
    gp, mp, pairs, fixed, moving, _, live = rec[0]
    prm, surv, info = live[4], live[7], live[12]
    S = int(info[KS.WI_SURV]); sv = surv[:S].copy(); nsurv.append(S)
    t0, t1 = prm[KS.WP_T0], prm[KS.WP_T1]
    rel, ab = prm[KS.WP_REL], prm[KS.WP_ABS]
    reps = 20
    for name, f, args in (("start", d_start, (gp, mp, pairs, sv, t0, reps, rel, ab)),
                          ("pose", d_pose, (gp, mp, pairs, sv, t0, reps)),
                          ("bound", d_bound, (gp, mp, pairs, sv, t0, t1, reps, rel)),
                          ("gjk", d_gjk, (gp, mp, pairs, sv, t0, t1, reps, rel, ab))):
        f(*args)
        t = pc(); f(*args); res[name].append((pc() - t) / (reps * S))
print("survivors median", np.median(nsurv))
for k, v in res.items():
    print(k, "us per survivor %.2f" % (1e6 * np.median(v)))
