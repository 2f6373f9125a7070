"""CPU time per call of pair_bound, of the pieces of _bounds_core, and of no-NRT copies of both.

Usage: PYTHONPATH=<tree> python bc_parts.py [case name]
Each variant is driven in an njit loop over 64 sub-intervals of the window with the arguments
_bounds_core passes it (same workspace); best of 7 batches of 100 x 64 calls. The "copy" rows compile
the tree's own source of _bounds_core and pair_bound again, with numba's reference counting (NRT)
and with ``_nrt=False``: same arithmetic, only the incref/decref differ.
"""
import inspect
import sys
import time

import numpy as np
from numba import njit

import monitor  # noqa: F401
import monitor.certify.kernels as K
import monitor.motion.kernel as MK
from monitor.bench.cases import make_cases
from monitor.motion.kernel import pair_bound, pair_workspace


def _compile(name, nrt):
    """Copies of _bounds_core and pair_bound (bc_<name>; pb_<name> calls bc_<name>), NRT on or off."""
    ns = dict(MK.__dict__)
    src = inspect.getsource(MK._bounds_core.py_func)
    exec(src[src.index("def "):].replace("def _bounds_core(", f"def bc_{name}("), ns)
    flags = dict(error_model="numpy", no_cpython_wrapper=True, no_cfunc_wrapper=True, _nrt=nrt)
    bc = njit(**flags)(ns[f"bc_{name}"])
    ns[f"bc_{name}"] = bc
    src = inspect.getsource(MK.pair_bound.py_func)
    exec(src[src.index("def "):].replace("def pair_bound(", f"def pb_{name}(")
         .replace("    _bounds_core(", f"    bc_{name}("), ns)
    return bc, njit(**flags)(ns[f"pb_{name}"])


bc_nrt, pb_nrt = _compile("nrt", True)
bc_nonrt, pb_nonrt = _compile("nonrt", False)


@njit
def drive(n, what, mp, ba, bb, t0, t1):
    """Calls variant ``what`` n x 64 times (see LABELS)."""
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
                MK._bounds_core(mp, ta, tb, need, xpos, xmat, trans, angle, ws)
                acc += trans[1]
            elif what == 2:
                bc_nrt(mp, ta, tb, need, xpos, xmat, trans, angle, ws)
                acc += trans[1]
            elif what == 3:
                bc_nonrt(mp, ta, tb, need, xpos, xmat, trans, angle, ws)
                acc += trans[1]
            elif what == 4:
                TA, angA, TB, angB = pb_nrt(mp, ba, bb, ta, tb, pA, RA, pB, RB, pws)
                acc += TA + angB
            elif what == 5:
                TA, angA, TB, angB = pb_nonrt(mp, ba, bb, ta, tb, pA, RA, pB, RB, pws)
                acc += TA + angB
            elif what == 6:
                lm = MK._locate(times, tm)
                MK._qpos_at(mp.qpos, mp.qt_adr, mp.qt_same, mp.qt_half, mp.qt_target, lm[0], lm[1], lm[2], qm)
                acc += qm[0]
            elif what == 7:
                MK._fk(mp.body_parent, mp.body_mocap, mp.body_pos, mp.body_quat, mp.body_jntadr,
                       mp.body_jntnum, mp.jnt_type, mp.jnt_qposadr, mp.jnt_pos, mp.jnt_axis, mp.jnt_axis_norm,
                       mp.qpos0, qm, need, xpos, xquat, xmat, janchor, jaxis, jframe, om, qu)
                acc += xpos[1, 0]
            elif what == 8:
                la = MK._locate(times, ta)
                lb = MK._locate(times, tb)
                lm = MK._locate(times, tm)
                lo = MK._search_right(times, ta)
                hi = MK._search_left(times, tb)
                acc += MK._rot_dev(times, mp.qpos, mp.qt_adr, mp.qt_cum, mp.qt_phi, 0, qu, ta, tb, tm, lm, lo,
                                   hi)
                acc += MK._vec_dev(mp.qpos, 0, qm, la, lb, lo, hi)
            elif what == 9:
                chain[0] = 2
                chain[1] = 3
                T2, Th2 = MK._velocity_bound(chain[:2], vkind, vrate, D, r0, suffix, rmax, 1e-3, 1e-15, 1.0,
                                             1.0, 1.0)
                acc += T2
    return acc


LABELS = ["pair_bound (as the tree compiles it)", "_bounds_core", "copy of _bounds_core, NRT",
          "copy of _bounds_core, _nrt=False", "pair_bound copy + copy, NRT",
          "pair_bound copy + copy, _nrt=False",
          "_qpos_at (after a _locate)", "_fk", "3 _locate + 2 searches + _rot_dev + _vec_dev",
          "_velocity_bound (L = 2)"]
nm = sys.argv[1] if len(sys.argv) > 1 else "rot-hull-box-near-1e-02"
c = {c.name: c for c in make_cases(seed=7, quick=True)}[nm]
s, m = c.scene(16), c.body_motion()
gp = K.scene_pack(s).geoms
mp = K.trajectory_pack(m)
ba, bb = int(gp.body[0]), int(gp.body[1])
ba = ba if mp.body_moving[ba] else -1
bb = bb if mp.body_moving[bb] else -1
t0, t1 = float(mp.times[0]), float(mp.times[-1])
print(f"{nm}: nbody {mp.body_parent.shape[0]} njnt {mp.jnt_type.shape[0]} K {mp.times.shape[0]} "
      f"moving bodies {ba}, {bb}")
for what, label in enumerate(LABELS):
    drive(1, what, mp, ba, bb, t0, t1)
    best = np.inf
    for _ in range(7):
        t = time.process_time()
        drive(100, what, mp, ba, bb, t0, t1)
        best = min(best, (time.process_time() - t) / (100 * 64))
    print(f"  {label:48s} {1e9 * best:8.0f} ns/call")
