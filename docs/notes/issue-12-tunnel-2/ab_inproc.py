"""In-process A/B of this branch's Plan fast paths and lazy witness vs main's code, interleaved rounds.

PYTHONPATH=<this tree> python docs/notes/issue-12-tunnel-2/ab_inproc.py [rounds]
"old" = main's Plan.body_poses validation (check_times_in_window), Segments.locate, _fk loop and
engine._find_witness (all candidates posed at once), patched back in; "new" = this tree (the
engine's survivor-routing loop is not switched: it is in both). Tunnel schedule of tunnel.py; medians of per-round means.
"""
import sys
import time

import mujoco
import numpy as np

from monitor.certify import engine
from monitor.certify.common import check_active_budget
from monitor.gate import Gate
from monitor.motion import _kinematics as K
from monitor.motion import plan as P


def old_times_ok(self, times):
    return K.check_times_in_window(times, self.window)


def old_locate(self, t):
    return self._seg.locate(t)


def old_fk(self, Q):
    m = self._model
    d = self._scratch
    T = Q.shape[0]
    pos = np.empty((T, m.nbody, 3))
    mat = np.empty((T, m.nbody, 3, 3))
    if m.nmocap:
        d.mocap_pos[:] = self._mocap_pos
        d.mocap_quat[:] = self._mocap_quat
    for k in range(T):
        if not k % 16:
            check_active_budget()
        d.qpos[:] = Q[k]
        mujoco.mj_kinematics(m, d)
        pos[k] = d.xpos
        mat[k] = d.xmat.reshape(m.nbody, 3, 3)
    return pos, mat


def old_find_witness(plan, ga, gb, times, margin, tol, budget=None):
    from monitor.geometry.distance import shape_distance

    pos, rot = plan.body_poses(times)
    slack = engine._approx(ga, gb)
    for k, t in enumerate(times):
        if budget is not None and budget.exhausted:
            return None
        d = shape_distance(ga.shape, (rot[k, ga.body_id], pos[k, ga.body_id]),
                           gb.shape, (rot[k, gb.body_id], pos[k, gb.body_id]), tolerances=tol)
        if d.upper + slack < margin:
            return engine.Witness(float(t), (ga.name, gb.name), 0.5 * (d.p_a + d.p_b), float(d.upper + slack))
    return None


NEW = (P.Plan._times_ok, P.Plan._locate, P.Plan._fk, engine._find_witness)
OLD = (old_times_ok, old_locate, old_fk, old_find_witness)


def use(fns):
    P.Plan._times_ok, P.Plan._locate, P.Plan._fk, engine._find_witness = fns


m = mujoco.MjModel.from_xml_path("/work/main/models/tunnel/scene.xml")
gate = Gate(m, margin=0.001)
d = mujoco.MjData(m)


def run(n):
    mujoco.mj_resetDataKeyframe(m, d, 0)
    gate.reset()
    out = []
    t = time.perf_counter()
    for k in range(n):
        target = 0.3 if (k // 25) % 2 == 0 else -0.3
        r = gate.step(d, np.clip([12.0 * (target - d.qpos[0])], -6, 6), nstep=1)
        c = r.certificate
        w = c.witness
        out.append((str(r.verdict), c.earliest_time, c.clearance,
                    None if w is None else (w.time, w.point.tobytes(), w.distance)))
    return (time.perf_counter() - t) / n, out, d.qpos.tobytes()


rounds = int(sys.argv[1]) if len(sys.argv) > 1 else 6
res = {"old": [], "new": []}
for fns in (OLD, NEW):
    use(fns)
    run(20)
ref = None
for _ in range(rounds):
    for name, fns in (("old", OLD), ("new", NEW)):
        use(fns)
        dt, out, q = run(100)
        res[name].append(dt)
        if ref is None:
            ref = (out, q)
        assert (out, q) == ref, "verdicts / times / clearances / final state differ"
o, n = np.median(res["old"]) * 1e6, np.median(res["new"]) * 1e6
print(f"old {o:.0f} us  new {n:.0f} us  old/new {o / n:.3f}  (per-round ratios "
      f"{[round(a / b, 3) for a, b in zip(res['old'], res['new'])]})")
