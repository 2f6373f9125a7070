"""Red team 14: "auto" against the previous path on every kind of joint (armcert's route test).

Usage: PYTHONPATH=<tree>:<tree>/tests:docs/notes/redteam-14 python routefuzz.py SEED0 NSEEDS [NBODY]

Per random model (tests/_pair_oracle.py: free / ball / hinge / slide / mocap / welded bodies), plans
of three kinds: still (every waypoint qpos0 plus one fixed random offset), rotation only (hinge /
ball coordinates change, slides and free positions held) and everything moving; margins 0 and
0.02 m, ongoing "violation" and "deepen". "auto" (engine._no_extrusion_route decides) must equal
the previous path (_no_extrusion_route forced False, _kernel_decided off): verdict, earliest time, clearance,
witness. Still plans also against the oracle's static distance at t0 (a pair the oracle proves
closer than the margin must not be certified).
"""
from __future__ import annotations

import sys
import warnings

import mujoco
import numpy as np
import redteam_oracle as O
from _pair_oracle import random_model
from armfuzz import _key, _old_path

import monitor
from monitor.certify import engine


def main() -> None:
    """Run the seeds given on the command line; print the counts."""
    s0, n = int(sys.argv[1]), int(sys.argv[2])
    big = int(sys.argv[3]) if len(sys.argv) > 3 else None   # bodies (+0..19), one geom each at most
    st = dict(cases=0, differ=0, whole_route=0, false_cert=0, certified=0, violation=0, uncertain=0)
    calls = []
    real = engine._no_extrusion_route

    def spy(mp, mov):
        r = real(mp, mov)
        calls.append(r)
        return r

    engine._no_extrusion_route = spy
    for seed in range(s0, s0 + n):
        rng = np.random.default_rng(seed)
        xml, _ = (random_model(seed, int(rng.integers(1, 12)), 2) if big is None
                  else random_model(seed, big + int(rng.integers(0, 20)), 1))
        m = mujoco.MjModel.from_xml_string(xml)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            scene = monitor.Scene.from_model(m, pairs=str(rng.choice(["mujoco", "all"])))
        if not len(scene.pair_ids) or not m.nq:
            continue
        for kind in ("still", "rotation", "all"):
            K = int(rng.integers(2, 6))
            q = np.repeat(m.qpos0[None], K, axis=0)
            off = rng.normal(0, 0.3, m.nq)
            for j in range(m.njnt):
                a, t = m.jnt_qposadr[j], m.jnt_type[j]
                if t == mujoco.mjtJoint.mjJNT_HINGE:
                    q[:, a] += off[a] + (0 if kind == "still" else np.linspace(0, rng.normal(0, 1.5), K))
                elif t == mujoco.mjtJoint.mjJNT_SLIDE:
                    q[:, a] += off[a] + (np.linspace(0, rng.normal(0, 0.3), K) if kind == "all" else 0)
                else:
                    lo = a + 3 if t == mujoco.mjtJoint.mjJNT_FREE else a
                    if t == mujoco.mjtJoint.mjJNT_FREE:
                        q[:, a:a + 3] += off[a:a + 3] + (np.linspace(0, 1, K)[:, None] * rng.normal(0, 0.3, 3)
                                                         if kind == "all" else 0)
                    axis = rng.normal(size=3)
                    ang = rng.normal(0, 1.0)
                    for k in range(K):
                        frac = 0.0 if kind == "still" else k / (K - 1)
                        q[k, lo:lo + 4] = O.axis_quat(axis, ang * (1 + frac))
            plan = monitor.Plan(np.linspace(0, 0.5, K), q, m)
            for margin, ongoing in ((0.0, "violation"), (0.02, "violation"), (0.0, "deepen")):
                st["cases"] += 1
                calls.clear()
                c = monitor.certify(scene, plan, margin=margin, ongoing=ongoing)
                st["whole_route"] += any(calls)
                st[str(c.verdict)] += 1
                engine._no_extrusion_route = real
                try:
                    o = _old_path(scene, plan, margin=margin, ongoing=ongoing)
                finally:
                    engine._no_extrusion_route = spy
                if _key(c) != _key(o):
                    st["differ"] += 1
                    print(seed, kind, margin, "auto != old", _key(c), _key(o), flush=True)
                if kind == "still" and ongoing == "violation" and str(c.verdict) == "certified":
                    orc = O.PlanOracle(m, plan.times if hasattr(plan, "times") else np.linspace(0, 0.5, K), q)
                    for ga, gb in scene.pair_ids.tolist():
                        if O.PLANE in (m.geom_type[ga], m.geom_type[gb]):
                            continue
                        a, b = orc.geoms(0.0, (ga, gb))
                        w = O.upper_distance(a, b)
                        if O.check_witness(a, b, w, slack=1e-9) and w.upper < margin - 1e-9:
                            st["false_cert"] += 1
                            print(seed, kind, margin, "FALSE CERTIFICATE", ga, gb, w.upper, flush=True)
    print(st)


if __name__ == "__main__":
    main()
