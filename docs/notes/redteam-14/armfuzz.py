"""Red team 14: rotating-only windows (hinge / ball chains) against the dense-sampling oracle.

Usage: PYTHONPATH=<tree>:<tree>/tests python armfuzz.py SEED0 NSEEDS

Per seed: a random hinge/ball chain (no slide/free joint: no translating moving body, so "auto"
takes engine._no_extrusion_route's whole-shape route) among static obstacles, a random joint plan
(2-12 waypoints). The closest pairs (sampled mj_geomDistance, plus every capsule-box pair, which
MuJoCo misses) get tests/redteam_oracle.motion_min (verified witnesses). The margin is set to the
oracle's minimum + delta (delta > 0: a verified violation exists, "certified" is a FALSE
CERTIFICATE) or minimum - delta. certify under "auto", "toleranced" and the previous path
(_no_extrusion_route forced False, _kernel_decided off), ongoing "violation" and "deepen".
A violation's witness is re-checked at its time: the oracle's verified upper bound below the margin,
or mj_geomDistance equal to the witness distance, or (penetration) a point found at positive depth in
both geoms (the oracle's upper bound is loose for mesh-capsule and cylinder-box contact).
"""

from __future__ import annotations

import sys
import warnings

import mujoco
import numpy as np
import redteam_oracle as O
from _pair_oracle import rotating_chain_xml as model_xml
from scipy.optimize import minimize

import monitor
from monitor.certify import engine


def _old_path(scene, plan, **kw):
    a, b = engine._no_extrusion_route, engine._kernel_decided
    engine._no_extrusion_route = lambda mpk, mov: False
    engine._kernel_decided = lambda *x, **k: None
    try:
        return monitor.certify(scene, plan, **kw)
    finally:
        engine._no_extrusion_route, engine._kernel_decided = a, b


def _key(c):
    w = c.witness
    return (str(c.verdict), c.earliest_time, c.clearance,
            None if w is None else (w.time, tuple(w.geoms), tuple(np.round(w.point, 15).tolist())))


def common_depth(a, b, z0) -> float:
    """Largest min(depth in a, depth in b) found by Nelder-Mead (> 0: a point proves the overlap).

    Started from z0 and the two centres; redteam_oracle.depth is a certified lower bound.
    """
    best = -np.inf
    for z in (z0, (a.p + b.p) / 2, a.p, b.p):
        r = minimize(lambda x: -min(O.depth(a, x), O.depth(b, x)), z, method="Nelder-Mead",
                     options=dict(xatol=1e-12, fatol=1e-14, maxiter=20000))
        best = max(best, min(O.depth(a, r.x), O.depth(b, r.x)))
    return best


def seeded_case(seed: int):
    """(model, scene, times (K,), qpos (K, nq), Plan) of one seed, or None (no candidate pair)."""
    rng = np.random.default_rng(seed)
    m = mujoco.MjModel.from_xml_string(model_xml(rng))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        scene = monitor.Scene.from_model(m, pairs=str(rng.choice(["mujoco", "all"])))
    if not len(scene.pair_ids):
        return None
    K = int(rng.integers(2, 13))
    amp = rng.uniform(0.2, 2.5)
    q = np.repeat(m.qpos0[None], K, axis=0)
    for j in range(m.njnt):
        a = m.jnt_qposadr[j]
        if m.jnt_type[j] == 3:
            q[:, a] += np.cumsum(rng.uniform(-amp, amp, K)) / np.sqrt(K) * 0.8
        else:
            axis = rng.normal(size=3)
            for k in range(K):
                q[k, a:a + 4] = O.axis_quat(axis, amp * k / max(K - 1, 1) * rng.uniform(0.3, 1.0))
    times = np.linspace(0.0, 1.0, K)
    return m, scene, times, q, monitor.Plan(times, q, m)


def seeded_cases(s0: int, n: int):
    """(seed, seeded_case(seed)) for the seeds s0 .. s0 + n - 1 that have a candidate pair."""
    for seed in range(s0, s0 + n):
        case = seeded_case(seed)
        if case is not None:
            yield seed, case


def main() -> None:
    """Run the seeds given on the command line; print the counts."""
    s0, n = int(sys.argv[1]), int(sys.argv[2])
    st = dict(cases=0, false_cert=0, bad_witness=0, auto_vs_old=0, auto_vs_tol=0, certified=0, violation=0,
              uncertain=0, errors=0)
    for seed, (m, scene, times, q, plan) in seeded_cases(s0, n):
        orc = O.PlanOracle(m, times, q)
        # pre-filter with sampled MuJoCo distances (not the last word: capsule-box always kept)
        d = mujoco.MjData(m)
        ts = np.linspace(0, 1, 120)
        dmin = np.full(len(scene.pair_ids), np.inf)
        for t in ts:
            d.qpos[:] = O.interp_qpos(m, times, q, t)
            mujoco.mj_kinematics(m, d)
            for k, (ga, gb) in enumerate(scene.pair_ids.tolist()):
                dmin[k] = min(dmin[k], mujoco.mj_geomDistance(m, d, ga, gb, 1.0, None))
        cb = [k for k, (ga, gb) in enumerate(scene.pair_ids.tolist())
              if {int(m.geom_type[ga]), int(m.geom_type[gb])} == {O.CAPSULE, O.BOX}]
        cand = sorted(set(np.argsort(dmin)[:3].tolist()) | set(cb))
        best = (np.inf, None)
        for k in cand:
            ga, gb = scene.pair_ids[k].tolist()
            if m.geom_type[ga] == O.PLANE or m.geom_type[gb] == O.PLANE:
                continue
            r = O.motion_min(orc, ga, gb, 0.0, 1.0, n=100, refine=2)
            if r.upper < best[0]:
                best = (r.upper, (ga, gb, r.time))
        if not np.isfinite(best[0]):
            continue
        for delta in (0.002, -0.002, 0.0005):
            margin = max(best[0] + delta, 0.0)
            for ongoing in ("violation", "deepen"):
                st["cases"] += 1
                kw = dict(margin=margin, ongoing=ongoing)
                try:
                    ca = monitor.certify(scene, plan, method="auto", **kw)
                    ct = monitor.certify(scene, plan, method="toleranced", **kw)
                    co = _old_path(scene, plan, method="auto", **kw)
                except monitor.errors.MonitorError as exc:
                    st["errors"] += 1
                    print(seed, "error", type(exc).__name__, str(exc)[:120])
                    continue
                st[str(ca.verdict)] += 1
                if _key(ca) != _key(co):
                    st["auto_vs_old"] += 1
                    print(seed, delta, ongoing, "auto != old path", _key(ca), _key(co), flush=True)
                if str(ca.verdict) != str(ct.verdict):
                    st["auto_vs_tol"] += 1
                    print(seed, delta, ongoing, "auto vs toleranced", ca.verdict, ct.verdict)
                if delta > 0 and ongoing == "violation" and best[0] + delta > 0:
                    for c, name in ((ca, "auto"), (ct, "tol"), (co, "old")):
                        if str(c.verdict) == "certified":
                            st["false_cert"] += 1
                            print(seed, delta, "FALSE CERTIFICATE", name, best, margin, flush=True)
                if str(ca.verdict) == "violation" and ca.witness is not None:
                    w = ca.witness
                    ids = [scene.geom(g).id for g in w.geoms]
                    a, b = orc.geoms(float(w.time), tuple(ids))
                    u = O.upper_distance(a, b)
                    inside = min(O.depth(a, w.point), O.depth(b, w.point))
                    d.qpos[:] = O.interp_qpos(m, times, q, float(w.time))
                    mujoco.mj_kinematics(m, d)
                    dmj = mujoco.mj_geomDistance(m, d, ids[0], ids[1], 1.0, None)
                    # confirmed by the oracle's verified upper bound, or by MuJoCo agreeing with the
                    # witness distance (a second, independent computation; the oracle's upper bound
                    # is loose for mesh-capsule contact)
                    if not (u.upper < margin + 1e-6 or inside > -1e-6 or abs(dmj - w.distance) < 1e-7
                            or (w.distance < 0 and common_depth(a, b, w.point) > 0)):
                        st["bad_witness"] += 1
                        print(seed, delta, ongoing, "witness unconfirmed", u.upper, margin, inside, w,
                              flush=True)
    print(st)


if __name__ == "__main__":
    main()
