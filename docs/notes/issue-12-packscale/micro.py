import gc
import statistics
import sys
import time

sys.path.insert(0, str(__import__("pathlib").Path(__file__).resolve().parent))
import numpy as np
from ab import capture, fresh

import monitor.certify.kernels as KS
import monitor.motion.pack as PK
from monitor.motion.plan import Plan, _structure

name = sys.argv[1] if len(sys.argv) > 1 else "pusher"
scene, got = capture(name, 20)
plans = [p for p, _ in got if type(p) is Plan]
N = 200

def t(fn, arg_fn, n=N):
    xs = []
    for i in range(n):
        a = arg_fn(i)
        s = time.perf_counter_ns(); fn(a); xs.append(time.perf_counter_ns() - s)
    return statistics.median(xs) / 1e3

pl = [fresh(plans[i % len(plans)]) for i in range(N)]
print("K", plans[0].times.shape, "nbody", plans[0].nbody, "nq", plans[0].model.nq, "nmocap", plans[0].model.nmocap,
      "quat", len(plans[0]._st.quat_joints))
gc.disable()
print("fresh(_trusted incl copies)", t(lambda p: fresh(p), lambda i: plans[i % len(plans)]))
src = plans[0]
tq = [(src.times.copy(), src.qpos.copy()) for _ in range(N)]
print("_trusted only", t(lambda a: Plan._trusted(a[0], a[1], src.model, mocap_pos=src.mocap_pos, mocap_quat=src.mocap_quat, tolerances=src._tol), lambda i: tq[i]))
print("_structure", t(lambda m: _structure(m), lambda i: src.model))
print("pack_trajectory", t(PK.pack_trajectory, lambda i: pl[i]))
mps = [PK.pack_trajectory(p) for p in pl]
print("_pack_agrees", t(lambda a: KS._pack_agrees(*a), lambda i: (pl[i], mps[i])))
print("static_key", t(lambda a: PK.static_key(a[1], KS._pack_static(a[0])), lambda i: (pl[i], mps[i])))
print("plan_data_agrees", t(lambda a: PK.plan_data_agrees(*a), lambda i: (pl[i], mps[i])))
st = PK._plan_static(pl[0])
print("_plan_static", t(PK._plan_static, lambda i: pl[i]))
print("_f64 times+qpos", t(lambda p: (PK._f64(p.times), PK._f64(p.qpos)), lambda i: pl[i]))
pl2 = [fresh(plans[i % len(plans)]) for i in range(N)]
print("trajectory_pack_memo", t(KS.trajectory_pack_memo, lambda i: pl2[i]))
# _derive_and_scale alone
def das(p):
    mp = mps[0]
    tol = mp.tol.copy(); tol[3] = 0.0
    PK._derive_and_scale(st.qpos0_mag, mp.times, mp.qpos, mp.qpos0, mp.jnt_type, mp.jnt_qposadr, mp.jnt_pos, mp.jnt_axis,
        mp.jnt_axis_norm, mp.jnt_track, mp.body_parent, mp.body_jntadr, mp.body_jntnum, mp.body_pos, mp.body_quat,
        mp.body_mocap, np.empty(mp.nbody, np.int64), np.empty(mp.nbody, np.int64), mp.ref_points, mp.qt_adr,
        mp.qt_target, mp.qt_half, mp.qt_phi, mp.qt_cum, mp.qt_same, tol)
print("_derive_and_scale (+copy)", t(das, lambda i: None))
orig = PK._derive_and_scale
PK._derive_and_scale = lambda *a: None
print("pack_trajectory, das no-op", t(PK.pack_trajectory, lambda i: pl[i]))
PK._derive_and_scale = orig
