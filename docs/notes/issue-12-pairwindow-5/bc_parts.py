"""CPU time per call of pair_bound and of the pieces of _bounds_core, on a bench pair-window motion.

Usage: PYTHONPATH=<tree> python bc_parts.py [case name]
Each piece is driven in an njit loop over 64 sub-intervals of the window, with the arguments
_bounds_core passes it (same workspace). Best of 7 batches.
"""
import sys
import time

import numpy as np
from numba import njit

import monitor  # noqa: F401
import monitor.certify.kernels as K
import monitor.motion.kernel as MK
from monitor.bench.cases import make_cases
from monitor.motion.kernel import pair_bound, pair_workspace


@njit(error_model="numpy", no_cfunc_wrapper=True)
def slerp_off(qpos, qt_adr, qt_same, qt_half, qt_target, k, i, s, at_end, out, off):
    adr = qt_adr[k]
    q = qpos
    if at_end:
        last = q.shape[0] - 1
        for c in range(4):
            out[off + c] = q[last, adr + c]
        return
    if qt_same[k, i] != 0 or s == 0.0:
        for c in range(4):
            out[off + c] = q[i, adr + c]
        return
    h = qt_half[k, i]
    den = MK._sinc(h)
    c0 = (1.0 - s) * MK._sinc((1.0 - s) * h) / den
    c1 = s * MK._sinc(s * h) / den
    for c in range(4):
        out[off + c] = c0 * q[i, adr + c] + c1 * qt_target[k, i, c]


@njit(error_model="numpy", no_cfunc_wrapper=True)
def qpos_at_noalloc(qpos, qt_adr, qt_same, qt_half, qt_target, i, s, at_end, out):
    nq = qpos.shape[1]
    for c in range(nq):
        out[c] = MK._lerp_col(qpos, c, i, s, at_end)
    for k in range(qt_adr.shape[0]):
        slerp_off(qpos, qt_adr, qt_same, qt_half, qt_target, k, i, s, at_end, out, qt_adr[k])


@njit(error_model="numpy", no_cfunc_wrapper=True)
def pb_plain(mp, ba, bb, ta, tb, pA_out, RA_out, pB_out, RB_out, pws):
    """pair_bound's code, compiled as its own function (not inline="always")."""
    need, xpos, xmat, trans, angle, ws = pws
    need[:] = 0
    for body in (ba, bb):
        if body >= 0:
            c = body
            while True:
                need[c] = 1
                if c == 0:
                    break
                c = mp.body_parent[c]
    MK._bounds_core(mp, ta, tb, need, xpos, xmat, trans, angle, ws)
    TA, angA, TB, angB = 0.0, 0.0, 0.0, 0.0
    if ba >= 0:
        TA, angA = trans[ba], angle[ba]
        for r in range(3):
            pA_out[r] = xpos[ba, r]
            for c in range(3):
                RA_out[r, c] = xmat[ba, r, c]
    if bb >= 0:
        TB, angB = trans[bb], angle[bb]
        for r in range(3):
            pB_out[r] = xpos[bb, r]
            for c in range(3):
                RB_out[r, c] = xmat[bb, r, c]
    return TA, angA, TB, angB


@njit(error_model="numpy", no_cfunc_wrapper=True)
def pb_idx(mp, ba, bb, ta, tb, pA_out, RA_out, pB_out, RB_out, pws):
    """pair_bound's code reading the workspace tuple by index (no unpacking into names)."""
    need = pws[0]
    need[:] = 0
    for body in (ba, bb):
        if body >= 0:
            c = body
            while True:
                need[c] = 1
                if c == 0:
                    break
                c = mp.body_parent[c]
    MK._bounds_core(mp, ta, tb, pws[0], pws[1], pws[2], pws[3], pws[4], pws[5])
    xpos, xmat, trans, angle = pws[1], pws[2], pws[3], pws[4]
    TA, angA, TB, angB = 0.0, 0.0, 0.0, 0.0
    if ba >= 0:
        TA, angA = trans[ba], angle[ba]
        for r in range(3):
            pA_out[r] = xpos[ba, r]
            for c in range(3):
                RA_out[r, c] = xmat[ba, r, c]
    if bb >= 0:
        TB, angB = trans[bb], angle[bb]
        for r in range(3):
            pB_out[r] = xpos[bb, r]
            for c in range(3):
                RB_out[r, c] = xmat[bb, r, c]
    return TA, angA, TB, angB


import inspect  # noqa: E402
_src = inspect.getsource(MK._bounds_core.py_func)
_ns = dict(MK.__dict__)
exec(_src.split("\n", 1)[1].replace("def _bounds_core(", "def bc_nonrt("), _ns)
bc_nonrt = njit(error_model="numpy", no_cpython_wrapper=True, no_cfunc_wrapper=True, _nrt=False)(_ns["bc_nonrt"])
exec(_src.split("\n", 1)[1].replace("def _bounds_core(", "def bc_copy("), _ns)
bc_copy = njit(error_model="numpy", no_cpython_wrapper=True, no_cfunc_wrapper=True)(_ns["bc_copy"])

_pbsrc = (inspect.getsource(pb_plain.py_func).split("\n", 1)[1].replace("def pb_plain(", "def pb_nonrt(")
          .replace("MK._bounds_core(", "bc_nonrt("))
_ns["bc_nonrt"] = bc_nonrt
exec(_pbsrc, _ns)
pb_nonrt = njit(error_model="numpy", no_cpython_wrapper=True, no_cfunc_wrapper=True, _nrt=False)(_ns["pb_nonrt"])


@njit
def drive(n, what, mp, ba, bb, t0, t1):
    pws = pair_workspace(mp)
    need, xpos, xmat, trans, angle, ws = pws
    (qm, xquat, janchor, jaxis, jframe, vkind, vanchor, vaxis, vcoef, vang, vrate, qu, om, chain, stack,
     p_ref, D, r0, suffix, rmax) = ws
    pA, pB, RA, RB = np.empty(3), np.empty(3), np.empty((3, 3)), np.empty((3, 3))
    pair_bound(mp, ba, bb, t0, t1, pA, RA, pB, RB, pws)   # fills need and the workspace
    times = mp.times
    acc = 0.0
    for _ in range(n):
        for j in range(64):
            ta = t0 + (t1 - t0) * j / 64.0
            tb = ta + (t1 - t0) / 64.0
            tm = 0.5 * (ta + tb)
            if what == 0:
                TA, angA, TB, angB = pair_bound(mp, ba, bb, ta, tb, pA, RA, pB, RB, pws)
                acc += TA + angB
            elif what == 1:
                la = MK._locate(times, ta)
                lb = MK._locate(times, tb)
                lm = MK._locate(times, tm)
                lo = MK._search_right(times, ta)
                hi = MK._search_left(times, tb)
                acc += la[1] + lb[1] + lm[1] + lo + hi
            elif what == 2:
                lm = MK._locate(times, tm)
                MK._qpos_at(mp.qpos, mp.qt_adr, mp.qt_same, mp.qt_half, mp.qt_target, lm[0], lm[1], lm[2], qm)
                acc += qm[0]
            elif what == 3:
                MK._fk(mp.body_parent, mp.body_mocap, mp.body_pos, mp.body_quat, mp.body_jntadr, mp.body_jntnum,
                       mp.jnt_type, mp.jnt_qposadr, mp.jnt_pos, mp.jnt_axis, mp.jnt_axis_norm, mp.qpos0,
                       qm, need, xpos, xquat, xmat, janchor, jaxis, jframe, om, qu)
                acc += xpos[1, 0]
            elif what == 4:
                la = MK._locate(times, ta)
                lb = MK._locate(times, tb)
                lm = MK._locate(times, tm)
                lo = MK._search_right(times, ta)
                hi = MK._search_left(times, tb)
                acc += MK._rot_dev(times, mp.qpos, mp.qt_adr, mp.qt_cum, mp.qt_phi, 0, qu, ta, tb, tm, lm, lo, hi)
                acc += MK._vec_dev(mp.qpos, 0, qm, la, lb, lo, hi)
            elif what == 5:
                MK._track_omega(mp.qpos, mp.qt_adr, mp.qt_target, mp.qt_phi, 0, 0, om)
                acc += om[0]
            elif what == 6:
                L = 2
                chain[0] = 2
                chain[1] = 3
                T2, Th2 = MK._velocity_bound(chain[:L], vkind, vrate, D, r0, suffix, rmax, 1e-3, 1e-15, 1.0,
                                             1.0, 1.0)
                acc += T2
            elif what == 8:
                MK._bounds_core(mp, ta, tb, need, xpos, xmat, trans, angle, ws)
                acc += trans[1]
            elif what == 9:
                vanchor[:] = 0.0
                vaxis[:] = 0.0
                vcoef[:] = 0.0
                vang[:] = 0.0
                vrate[:] = 0.0
                acc += vang[0]
            elif what == 10:
                need[:] = 0
                for body in (ba, bb):
                    if body >= 0:
                        c = body
                        while True:
                            need[c] = 1
                            if c == 0:
                                break
                            c = mp.body_parent[c]
                acc += need[1]
            elif what == 11:
                for r in range(3):
                    pA[r] = xpos[ba, r]
                    for c in range(3):
                        RA[r, c] = xmat[ba, r, c]
                acc += pA[0]
            elif what == 12:
                TA, angA, TB, angB = pb_plain(mp, ba, bb, ta, tb, pA, RA, pB, RB, pws)
                acc += TA + angB
            elif what == 13:
                need[:] = 0
                for body in (ba, bb):
                    if body >= 0:
                        c = body
                        while True:
                            need[c] = 1
                            if c == 0:
                                break
                            c = mp.body_parent[c]
                MK._bounds_core(mp, ta, tb, need, xpos, xmat, trans, angle, ws)
                acc += trans[1]
            elif what == 14:
                need[0] = 1
                need[1] = 1
                need[2] = 0
                MK._bounds_core(mp, ta, tb, need, xpos, xmat, trans, angle, ws)
                acc += trans[1]
            elif what == 15:
                MK._bounds_core(mp, ta, tb, need, xpos, xmat, trans, angle, ws)
                for r in range(3):
                    pA[r] = xpos[ba, r]
                    for c in range(3):
                        RA[r, c] = xmat[ba, r, c]
                acc += trans[1]
            elif what == 16:
                MK._bounds_core(mp, ta, tb, need, xpos, xmat, trans, angle, ws)
                acc += trans[1] + xmat[1, 0, 0] + xpos[1, 2]
            elif what == 17:
                lm = MK._locate(times, tm)
                qpos_at_noalloc(mp.qpos, mp.qt_adr, mp.qt_same, mp.qt_half, mp.qt_target, lm[0], lm[1], lm[2], qm)
                acc += qm[0]
            elif what == 18:
                TA, angA, TB, angB = pb_idx(mp, ba, bb, ta, tb, pA, RA, pB, RB, pws)
                acc += TA + angB
            elif what == 19:
                bc_copy(mp, ta, tb, need, xpos, xmat, trans, angle, ws)
                acc += trans[1]
            elif what == 20:
                bc_nonrt(mp, ta, tb, need, xpos, xmat, trans, angle, ws)
                acc += trans[1]
            elif what == 21:
                TA, angA, TB, angB = pb_nonrt(mp, ba, bb, ta, tb, pA, RA, pB, RB, pws)
                acc += TA + angB
            elif what == 7:
                qu[0] = 1.0
                MK._quat_normalize(qu)
                acc += MK._chord(0.01 + 1e-9 * j)
    return acc


names = ["loop only", "pair_bound", "3 locate + 2 searches", "_qpos_at", "_fk", "locates+_rot_dev+_vec_dev",
         "_track_omega", "_velocity_bound (L=2)", "_quat_normalize+_chord", "_bounds_core", "5 zeroings", "need walk", "copy out", "pair_bound not inlined", "need walk + _bounds_core", "need=1,1,0 + _bounds_core", "_bounds_core + copy out", "_bounds_core + read xmat", "qpos_at without alloc", "pb reading pws by index", "_bounds_core copy", "_bounds_core copy _nrt=False", "pair_bound+_bounds_core _nrt=False"]
nm = sys.argv[1] if len(sys.argv) > 1 else "rot-hull-box-near-1e-02"
cases = {c.name: c for c in make_cases(seed=7, quick=True)}
c = cases[nm]
s, m = c.scene(16), c.body_motion()
gp = K.scene_pack(s).geoms
mp = K.trajectory_pack(m)
ga, gb = 0, 1
ba, bb = int(gp.body[ga]), int(gp.body[gb])
ba = ba if mp.body_moving[ba] else -1
bb = bb if mp.body_moving[bb] else -1
t0, t1 = float(mp.times[0]), float(mp.times[-1])
print(f"{nm}: nbody {mp.body_parent.shape[0]} njnt {mp.jnt_type.shape[0]} K {mp.times.shape[0]} "
      f"moving bodies {ba}, {bb}")
for what in (-1, 0, 8, 19, 20, 21):
    drive(1, what, mp, ba, bb, t0, t1)
    best = np.inf
    for _ in range(7):
        t = time.process_time()
        drive(100, what, mp, ba, bb, t0, t1)
        best = min(best, (time.process_time() - t) / (100 * 64))
    print(f"  {names[what + 1]:28s} {1e9 * best:8.0f} ns/call")
