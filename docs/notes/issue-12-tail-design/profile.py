"""Q2 / Q3(a-c): the brake's motion from the window ends a workload visits, over 2 s.

PYTHONPATH=<tree> python docs/notes/issue-12-tail-design/profile.py WORK BLOCKS EVERY [CERT]

Runs WORK (wl.py) gated at the defaults; every EVERY-th braking tail, keeps the window's end
state (the tail's start, ``Rollout._end_state``) and the brake control the gate held. Then,
from each kept start, holds that brake for 2 s of ``mj_step`` (the gate's tail is the first
``brake_steps`` of them, bit for bit: same state, same control, same stepping) and reports:
* max |qvel| (the gate's rest test) at 0, 0.05, 0.1, 0.25, 0.5, 1, 2 s (medians over starts,
  p90), the first time it is <= brake_vel_tol (1e-3), its minimum over 2 s;
* the relative rest criteria: first time max|qvel| <= 10 % / 1 % of its value at the start,
  kinetic energy <= 1 % / 0.01 % of the start's;
* the motion left after a tail of H s: max over [H, 2 s] of the largest body origin
  displacement from its position at H (m), for H = 0.05, 0.1, 0.25, 0.5, 1;
* what holds the velocity up at 1 s: the dof with the largest |qvel|, contacts; the most sign
  changes of one dof's velocity over 2 s (servo oscillation);
* CERT=1: the brake motion [0, H] certified with the gate's scene and request for H = 0.05,
  0.1, 0.25, 0.5, 1, 2 s: how often a tail certified at H is NOT certified at a longer horizon.
Prints "PROFILE {...}".
"""
import json, sys

import mujoco
import numpy as np

import wl

work, blocks, every = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
do_cert = len(sys.argv) > 4 and sys.argv[4] == "1"
W, starts = wl.brake_starts(work, blocks, every)
g, m = W.gate, W.model

dt = m.opt.timestep
T_END = 2.0
N = int(round(T_END / dt))
marks = [0.0, 0.05, 0.1, 0.25, 0.5, 1.0, 2.0]
idx = {t: int(round(t / dt)) for t in marks}
tol = g.brake_vel_tol
INTEG = mujoco.mjtState.mjSTATE_INTEGRATION
d = mujoco.MjData(m)
recs = []
cert_rows = []
for state, brake, mp, mq in starts:
    mujoco.mj_setState(m, d, state, INTEG)
    d.ctrl[:] = brake
    q = np.empty((N + 1, m.nq)); v = np.empty((N + 1, m.nv)); t = np.empty(N + 1)
    ke = np.empty(N + 1); xp = np.empty((N + 1, m.nbody, 3))
    M = np.zeros((m.nv, m.nv))
    def rec(k):
        q[k] = d.qpos; v[k] = d.qvel; t[k] = d.time
        mujoco.mj_kinematics(m, d)
        xp[k] = d.xpos
    rec(0)
    mujoco.mj_forward(m, d)
    mujoco.mj_fullM(m, d, M)  # mujoco >= 3.3 signature (m, d, dst)
    ke0 = 0.5 * v[0] @ M @ v[0]
    info1 = None
    for k in range(1, N + 1):
        mujoco.mj_step(m, d)
        rec(k)
        if k == idx[1.0]:
            mujoco.mj_forward(m, d)
            j = int(np.argmax(np.abs(d.qvel)))
            dof_joint = int(m.dof_jntid[j])
            info1 = {"dof": mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_JOINT, dof_joint) or str(dof_joint),
                     "ncon": int(d.ncon), "qfrc_bias_max": float(np.abs(d.qfrc_bias).max())}
    # kinetic energy with the mass matrix at each state would cost mj_forward per substep: use M at
    # the start (the relative KE criterion is about orders of magnitude)
    ke = 0.5 * np.einsum("ki,ij,kj->k", v, M, v)
    vmax = np.abs(v).max(axis=1)
    def first(mask):
        w = np.flatnonzero(mask)
        return float(w[0] * dt) if len(w) else None
    sgn = np.sign(v)
    flips = int(((sgn[1:] * sgn[:-1]) < 0).sum(axis=0).max())   # most velocity reversals of one dof in 2 s
    r = {"flips": flips, "vmax": {str(tm): float(vmax[idx[tm]]) for tm in marks},
         "t_rest_tol": first(vmax <= tol), "vmax_min": float(vmax.min()),
         "t_rel10": first(vmax <= 0.1 * vmax[0]), "t_rel1": first(vmax <= 0.01 * vmax[0]),
         "t_ke1": first(ke <= 1e-2 * ke0), "t_ke001": first(ke <= 1e-4 * ke0),
         "left_after": {}, "at_1s": info1}
    for H in (0.05, 0.1, 0.25, 0.5, 1.0):
        k = idx[H]
        r["left_after"][str(H)] = float(np.linalg.norm(xp[k:] - xp[k], axis=2).max())
    recs.append(r)
    if do_cert:
        cert_rows.append((t.copy(), q.copy(), mp, mq))

def med(xs, p=50):
    xs = [x for x in xs if x is not None]
    return float(np.percentile(xs, p)) if xs else None

out = {"work": work, "starts": len(recs), "timestep": dt, "brake_steps": g.brake_steps, "vel_tol": tol,
       "nq": m.nq, "nv": m.nv, "gravity": list(m.opt.gravity),
       "vmax_median": {str(tm): med([r["vmax"][str(tm)] for r in recs]) for tm in marks},
       "vmax_p90": {str(tm): med([r["vmax"][str(tm)] for r in recs], 90) for tm in marks},
       "reach_tol_within_2s": sum(r["t_rest_tol"] is not None for r in recs),
       "t_rest_tol_median": med([r["t_rest_tol"] for r in recs]),
       "t_rest_tol_p90": med([r["t_rest_tol"] for r in recs], 90),
       "velocity_reversals_2s_median": med([r["flips"] for r in recs]),
       "vmax_min_median": med([r["vmax_min"] for r in recs]),
       "t_rel10": {"n": sum(r["t_rel10"] is not None for r in recs), "median": med([r["t_rel10"] for r in recs]),
                   "p90": med([r["t_rel10"] for r in recs], 90)},
       "t_rel1": {"n": sum(r["t_rel1"] is not None for r in recs), "median": med([r["t_rel1"] for r in recs]),
                  "p90": med([r["t_rel1"] for r in recs], 90)},
       "t_ke1": {"n": sum(r["t_ke1"] is not None for r in recs), "median": med([r["t_ke1"] for r in recs]),
                 "p90": med([r["t_ke1"] for r in recs], 90)},
       "t_ke001": {"n": sum(r["t_ke001"] is not None for r in recs), "median": med([r["t_ke001"] for r in recs]),
                   "p90": med([r["t_ke001"] for r in recs], 90)},
       "left_after_median_m": {H: med([r["left_after"][H] for r in recs]) for H in recs[0]["left_after"]},
       "left_after_max_m": {H: max(r["left_after"][H] for r in recs) for H in recs[0]["left_after"]},
       "at_1s_dofs": dict(__import__("collections").Counter(r["at_1s"]["dof"] for r in recs)),
       "at_1s_ncon_median": med([r["at_1s"]["ncon"] for r in recs]),
       }
if do_cert:
    from monitor.certify.engine import certify
    from monitor.motion.plan import Plan
    scene, req = g.scene, g.request
    Hs = (0.05, 0.1, 0.25, 0.5, 1.0, 2.0)
    table = []
    late = []   # brakes certified over the default horizon whose motion is a violation later
    for j, (t, q, mp, mq) in enumerate(cert_rows):
        row = {}
        for H in Hs:
            k = idx[H] if H in idx else int(round(H / dt))
            p = Plan._trusted(t[:k + 1].copy(), q[:k + 1].copy(), model=m, mocap_pos=mp.copy(), mocap_quat=mq.copy())
            c = certify(scene, p, request=req)
            row[H] = str(c.verdict)
            if row.get(0.25) == "certified" and H > 0.25 and row[H] == "violation" and len(late) < 10 and (
                    not late or late[-1]["start"] != j):
                w = c.witness
                late.append({"start": j, "horizon": H, "witness_time_after_tail_start": float(w.time - t[0]),
                             "pair": [str(x) for x in getattr(w, "geoms", getattr(w, "pair", ()))],
                             "vmax_at_0.25": recs[j]["vmax"]["0.25"]})
        table.append(row)
    out["late_violations"] = late
    out["brake_certified_at"] = {str(H): sum(r[H] == "certified" for r in table) for H in Hs}
    out["brake_violation_at"] = {str(H): sum(r[H] == "violation" for r in table) for H in Hs}
    out["certified_short_not_long"] = {
        f"{a}->{b}": sum(r[a] == "certified" and r[b] != "certified" for r in table)
        for a in Hs for b in Hs if a < b}
print("PROFILE " + json.dumps(out))
