"""Red team 14: rotating-only windows in scenes of 400+ geoms (stage 0's sweep + the whole-shape route).

Usage: PYTHONPATH=<tree>:<tree>/tests:docs/notes/redteam-14 python armbig.py SEED0 NSEEDS [NOBST]

A random hinge / ball chain (tests/_pair_oracle.rotating_chain_xml) plus NOBST (default 450) small
static spheres / boxes scattered in a 1.2 m cube (engine.SWEEP_MIN_GEOMS = 400: stage 0 sweeps).
Margin = the oracle's verified minimum over the 6 closest pairs (sampled MuJoCo distances) +
0.002 m: never certified; "auto" equals the previous path.
"""
from __future__ import annotations

import sys
import warnings

import mujoco
import numpy as np
import redteam_oracle as O
from _pair_oracle import rotating_chain_xml, rotating_qpos
from armfuzz import _key, _old_path

import monitor


def main() -> None:
    """Run the seeds given on the command line; print the counts."""
    s0, n = int(sys.argv[1]), int(sys.argv[2])
    nob = int(sys.argv[3]) if len(sys.argv) > 3 else 450
    st = dict(cases=0, false_cert=0, differ=0, certified=0, violation=0, uncertain=0)
    for seed in range(s0, s0 + n):
        rng = np.random.default_rng(seed)
        xml = rotating_chain_xml(rng)
        extra = "".join(
            f'<geom name="x{k}" type="{"sphere" if k % 2 else "box"}" '
            f'size="{" ".join([f"{rng.uniform(0.005, 0.02):.3f}"] * (1 if k % 2 else 3))}" '
            f'pos="{" ".join(f"{v:.4f}" for v in rng.uniform(-0.6, 0.6, 3))}"/>' for k in range(nob))
        xml = xml.replace("<worldbody>", "<worldbody>" + extra, 1)
        m = mujoco.MjModel.from_xml_string(xml)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            scene = monitor.Scene.from_model(m)
        K = int(rng.integers(2, 8))
        q = rotating_qpos(m, rng, K)
        times = np.linspace(0, 1, K)
        plan = monitor.Plan(times, q, m)
        d = mujoco.MjData(m)
        dmin = np.full(len(scene.pair_ids), np.inf)
        for t in np.linspace(0, 1, 60):
            d.qpos[:] = O.interp_qpos(m, times, q, t)
            mujoco.mj_kinematics(m, d)
            for k, (ga, gb) in enumerate(scene.pair_ids.tolist()):
                dmin[k] = min(dmin[k], mujoco.mj_geomDistance(m, d, ga, gb, 0.5, None))
        orc = O.PlanOracle(m, times, q)
        best = np.inf
        for k in np.argsort(dmin)[:6].tolist():
            ga, gb = scene.pair_ids[k].tolist()
            if O.PLANE in (m.geom_type[ga], m.geom_type[gb]):
                continue
            best = min(best, O.motion_min(orc, ga, gb, 0, 1, n=80, refine=1).upper)
        if not np.isfinite(best):
            continue
        for margin in (max(best, 0.0) + 0.002, max(best - 0.002, 0.0)):
            st["cases"] += 1
            c = monitor.certify(scene, plan, margin=margin)
            o = _old_path(scene, plan, margin=margin)
            st[str(c.verdict)] += 1
            if _key(c) != _key(o):
                st["differ"] += 1
                print(seed, margin, "auto != old", _key(c)[:3], _key(o)[:3], flush=True)
            if margin > best and str(c.verdict) == "certified":
                st["false_cert"] += 1
                print(seed, margin, best, "FALSE CERTIFICATE", flush=True)
    print(st)


if __name__ == "__main__":
    main()
