"""Per-call cost of the motion bound (pair_bound / _bounds_core) on captured Arm packs."""
import sys, time, statistics
import numpy as np, gymnasium as gym
from numba import njit
import monitor.envs  # noqa
import monitor.certify.engine as E
import monitor.certify.kernels as KS
import monitor.motion.kernel as KN
from monitor.gym_gate import SafetyGate
cap = []
_c = E.certify
def c(scene, plan, *a, **k):
    r = _c(scene, plan, *a, **k); cap.append((scene, plan)); return r
E.certify = c
env = SafetyGate(gym.make("monitor/Arm-v0"))
env.reset(seed=0); env.action_space.seed(0)
for a in [env.action_space.sample() for _ in range(6)]: env.step(a)
E.certify = _c

@njit(cache=False)
def loop_pair(mp, ba, bb, ta, tb, n):
    pws = KN.pair_workspace(mp)
    pA = np.empty(3); pB = np.empty(3); RA = np.empty((3, 3)); RB = np.empty((3, 3))
    acc = 0.0
    for k in range(n):
        f = k / n
        a = ta + (tb - ta) * 0.5 * f
        TA, aA, TB, aB = KN.pair_bound(mp, ba, bb, a, tb, pA, RA, pB, RB, pws)
        acc += TA + TB
    return acc

@njit(cache=False)
def loop_tree(mp, ta, tb, n):
    nb = mp.body_parent.shape[0]
    ws = KN.bounds_workspace(mp)
    need = np.ones(nb, np.int64)
    xpos = np.empty((nb, 3)); xmat = np.empty((nb, 3, 3)); tr = np.zeros(nb); an = np.zeros(nb)
    acc = 0.0
    for k in range(n):
        f = k / n
        a = ta + (tb - ta) * 0.5 * f
        KN._bounds_core(mp, a, tb, need, xpos, xmat, tr, an, ws)
        acc += tr[1]
    return acc

m = env.unwrapped.model
print("nbody", m.nbody, "njnt", m.njnt, "nq", m.nq)
for scene, plan in cap[:4]:
    mp = KS.trajectory_pack(plan)
    K = len(plan.times)
    ta, tb = float(plan.times[0]), float(plan.times[-1])
    nb = mp.body_parent.shape[0]
    ba, bb = nb - 1, 2
    for (lab, a, b) in (("whole", ta, tb), ("1seg", ta, float(plan.times[1]))):
        loop_pair(mp, ba, bb, a, b, 10); loop_tree(mp, a, b, 10)
        N = 20000
        t = time.perf_counter(); loop_pair(mp, ba, bb, a, b, N); dp = (time.perf_counter() - t) / N * 1e6
        t = time.perf_counter(); loop_tree(mp, a, b, N); dt = (time.perf_counter() - t) / N * 1e6
        print(f"K {K:4d} {lab:6s} pair_bound {dp:.3f} us   tree(_bounds_core all) {dt:.3f} us")

@njit(cache=False)
def loop_parts(mp, ta, tb, n, which):
    nb = mp.body_parent.shape[0]
    ws = KN.bounds_workspace(mp)
    (qm, xquat, janchor, jaxis, jframe, vkind, vanchor, vaxis, vcoef, vang, vrate, qu, om, chain, stack,
     p_ref, D, r0, suffix, rmax) = ws
    need = np.ones(nb, np.int64)
    xpos = np.empty((nb, 3)); xmat = np.empty((nb, 3, 3))
    acc = 0.0
    times = mp.times
    for k in range(n):
        f = k / n
        a = ta + (tb - ta) * 0.5 * f
        tm = 0.5 * (a + tb)
        if which == 0:
            la = KN._locate(times, a); lb = KN._locate(times, tb); lm = KN._locate(times, tm)
            lo = KN._search_right(times, a); hi = KN._search_left(times, tb)
            acc += la[1] + lb[1] + lm[1] + lo + hi
        elif which == 1:
            lm = KN._locate(times, tm)
            KN._qpos_at(mp.qpos, mp.qt_adr, mp.qt_same, mp.qt_half, mp.qt_target, lm[0], lm[1], lm[2], qm)
            acc += qm[0]
        elif which == 2:
            KN._fk(mp.body_parent, mp.body_mocap, mp.body_pos, mp.body_quat, mp.body_jntadr, mp.body_jntnum, mp.jnt_type,
                   mp.jnt_qposadr, mp.jnt_pos, mp.jnt_axis, mp.jnt_axis_norm, mp.qpos0,
                   qm, need, xpos, xquat, xmat, janchor, jaxis, jframe, om, qu)
            acc += xpos[1, 0]
        elif which == 3:
            la = KN._locate(times, a); lb = KN._locate(times, tb)
            lo = KN._search_right(times, a); hi = KN._search_left(times, tb)
            for j in range(3):
                acc += KN._col_dev(mp.qpos, j, qm[j], la, lb, lo, hi)
    return acc
names = ["locate x3+search x2", "locate+qpos_at", "fk", "col_dev x3 (+locates)"]
for scene, plan in cap[:2]:
    mp = KS.trajectory_pack(plan)
    ta, tb = float(plan.times[0]), float(plan.times[-1])
    for w in range(4):
        loop_parts(mp, ta, tb, 10, w)
        N = 50000
        t = time.perf_counter(); loop_parts(mp, ta, tb, N, w); d = (time.perf_counter() - t) / N * 1e6
        print(f"{names[w]:25s} {d:.3f} us")
