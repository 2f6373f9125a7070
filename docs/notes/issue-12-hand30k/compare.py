"""Record every certify call of seeded gated runs (hand30 with several target seeds, Arm-v0): one JSON line each.

usage: PYTHONPATH=<tree> python compare.py OUT HAND_SEEDS ARM_BLOCKS [ORACLE]
Per call: workload, index, K (waypoints), verdict, clearance, witness (time, pair), earliest, tests,
pairs_culled, and per-pair (verdict, method) of the non-culled pairs. ORACLE=1: for hand30 certified
calls, min over 24 sample times and all selected pairs of mujoco.mj_geomDistance (independent oracle).
"""
import json, sys
import numpy as np
import mujoco
sys.path.insert(0, str(__import__("pathlib").Path(__file__).resolve().parents[1] / "issue-12-tail-design"))
import wl
import monitor.certify.engine as E

out = open(sys.argv[1], "w")
hand_seeds = [int(x) for x in sys.argv[2].split(",")] if sys.argv[2] else []
arm_blocks = int(sys.argv[3])
oracle = len(sys.argv) > 4 and sys.argv[4] == "1"
cur = {"work": None, "i": 0}
orc = {"n": 0, "bad": 0, "minslack": np.inf}
_cert = E.certify


def pairs_of(scene):
    return [(int(a), int(b)) for a, b in scene.pair_ids]


def oracle_check(scene, plan, c, model):
    d = mujoco.MjData(model)
    ts = np.linspace(plan.times[0], plan.times[-1], 24)
    Q = plan.qpos_at(ts)
    dmin = np.inf
    ids = [g.id for g in scene.geoms]
    for q in Q:
        d.qpos[:] = q
        if model.nmocap:
            d.mocap_pos[:] = plan.mocap_pos
            d.mocap_quat[:] = plan.mocap_quat
        mujoco.mj_kinematics(model, d)
        for a, b in scene.pair_ids:
            ga, gb = ids[a], ids[b]
            dist = mujoco.mj_geomDistance(model, d, ga, gb, 0.05, None)
            dmin = min(dmin, dist)
    orc["n"] += 1
    slack = dmin - c.clearance
    orc["minslack"] = min(orc["minslack"], slack)
    if slack < -1e-6:
        orc["bad"] += 1


def certify(scene, plan, **k):
    c = _cert(scene, plan, **k)
    w = c.witness
    rec = {"work": cur["work"], "i": cur["i"], "K": len(plan.times), "verdict": str(c.verdict),
           "clearance": float(c.clearance), "earliest": None if c.earliest_time is None else float(c.earliest_time),
           "witness": None if w is None else [float(w.time), list(map(str, w.geoms)) if hasattr(w, "geoms") else str(w)],
           "tests": int(c.stats["tests"]), "culled": int(c.stats["pairs_culled"]),
           "pairs": sorted([list(map(str, p.geoms)) + [str(p.verdict), str(p.method)] for p in c.pairs
                            if str(p.method) != "culled"])}
    out.write(json.dumps(rec) + "\n")
    cur["i"] += 1
    if oracle and cur["work"].startswith("hand30") and str(c.verdict) == "certified" and cur["model"] is not None:
        oracle_check(scene, plan, c, cur["model"])
    return c


E.certify = certify
for seed in hand_seeds:
    W = wl.make("hand30")
    m = W.model
    lo, hi = m.actuator_ctrlrange[:, 0], m.actuator_ctrlrange[:, 1]
    targets = np.random.default_rng(seed).uniform(lo, hi, size=(64, m.nu))
    W.ctrl = lambda d, k, t=targets: t[(k // 10) % len(t)]
    cur.update(work=f"hand30/{seed}", i=0, model=m)
    for _ in W.steps(40, 0):
        pass
if arm_blocks:
    W = wl.make("monitor/Arm-v0")
    cur.update(work="arm", i=0, model=None)
    for rep in range(arm_blocks):
        for _ in W.steps(30, rep):
            pass
out.close()
print("oracle", orc)
