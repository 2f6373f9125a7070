"""Red team 16, idea (3) on BodyMotion: quaternion columns that change only in a sign bit
(-0.0), by a whole sign flip (q -> -q, the same rotation), by one ulp, or not at all, with
translating bodies among static shapes; every method, both ongoing modes, t0 = -0.0.
Prints one line per call (as onecall_fuzz.py) for diffing trees / flag settings;
--oracle checks certified calls by dense sampling (tests/redteam_oracle.py, BodyMotionOracle /
TrajectoryOracle) and re-checks violation witnesses.
Usage: PYTHONPATH=<tree> python bodymotion_fuzz.py N SEED [--off] [--oracle]
"""
import sys

import mujoco
import numpy as np

import monitor
from monitor.certify import engine

sys.path.insert(0, "/work/wt/rt16/tests")
sys.path.insert(0, __file__.rsplit("/", 1)[0])
import redteam_oracle as O  # noqa: E402
from onecall_fuzz import fmt  # noqa: E402


def make(rng):
    lines = ['<mujoco><option><flag contact="disable"/></option><worldbody>']
    for i in range(int(rng.integers(1, 4))):
        kind = rng.choice(["box", "capsule", "sphere"])
        size = {"box": rng.uniform(0.05, 0.3, 3), "capsule": rng.uniform(0.03, 0.2, 2),
                "sphere": rng.uniform(0.05, 0.3, 1)}[kind]
        q = rng.normal(size=4)
        lines.append(f'<geom name="s{i}" type="{kind}" size="{fmt(size)}" pos="{fmt(rng.uniform(-0.6, 0.6, 3))}" '
                     f'quat="{fmt(q / np.linalg.norm(q))}"/>')
    nb = int(rng.integers(1, 4))
    for b in range(nb):
        kind = rng.choice(["box", "capsule", "sphere"])
        size = {"box": rng.uniform(0.03, 0.15, 3), "capsule": rng.uniform(0.02, 0.1, 2),
                "sphere": rng.uniform(0.03, 0.15, 1)}[kind]
        q = rng.normal(size=4)
        lines.append(f'<body name="b{b}" mocap="true"><geom name="g{b}" type="{kind}" size="{fmt(size)}" '
                     f'pos="{fmt(rng.uniform(-0.05, 0.05, 3))}" quat="{fmt(q / np.linalg.norm(q))}"/></body>')
    lines.append("</worldbody></mujoco>")
    return "\n".join(lines)


def main(n, seed, off=False, oracle=False):
    if off:
        engine._ONE_CALL = False
    rng = np.random.default_rng(seed)
    nc, bad = {}, 0
    for i in range(n):
        m = mujoco.MjModel.from_xml_string(make(rng))
        K = int(rng.integers(2, 7))
        times = np.concatenate([[0.0], np.cumsum(rng.uniform(0.05, 1.0, K - 1))])
        if rng.random() < 0.3:
            times[0] = -0.0
        nb = m.nbody
        pos = np.zeros((K, nb, 3))
        quat = np.zeros((K, nb, 4))
        quat[:, :, 0] = 1.0
        modes = []
        for b in range(1, nb):
            pos[:, b] = np.cumsum(rng.uniform(-0.25, 0.25, (K, 3)), axis=0) + rng.uniform(-0.5, 0.5, 3)
            u = rng.normal(size=4)
            u /= np.linalg.norm(u)
            mode = rng.choice(["none", "signbit", "flip", "ulp", "rotate"])
            modes.append(mode)
            quat[:, b] = u
            if mode == "signbit":
                quat[:, b] = [1.0, 0.0, 0.0, 0.0]
                quat[1::2, b, 2] = -0.0
            elif mode == "flip":
                quat[1::2, b] = -u
            elif mode == "ulp":
                quat[1::2, b, 1] = np.nextafter(u[1], 2.0)
            elif mode == "rotate":
                Q = rng.normal(size=(K, 4))
                quat[:, b] = Q / np.linalg.norm(Q, axis=1, keepdims=True)
        try:
            bm = monitor.BodyMotion(times, pos, quat, model=m)
        except TypeError:
            bm = monitor.BodyMotion(times, pos, quat)
        except Exception as e:   # noqa: BLE001
            print(i, "motion-error", type(e).__name__, str(e)[:80])
            continue
        scene = monitor.Scene.from_model(m, pairs="all")
        margin = float(rng.choice([0.0, 0.001, 0.02]))
        meth = str(rng.choice(["auto", "auto", "extrusion", "toleranced"]))
        og = str(rng.choice(["violation", "deepen"]))
        try:
            c = monitor.certify(scene, bm, margin=margin, epsilon=1e-3, method=meth, ongoing=og)
        except Exception as e:   # noqa: BLE001
            print(i, "error", type(e).__name__, str(e)[:120])
            continue
        d = c.to_dict()
        d["stats"].pop("wall_seconds", None)
        print(i, repr(d))
        v = c.verdict.value
        nc[v] = nc.get(v, 0) + 1
        if oracle and og == "violation":
            orc = O.TrajectoryOracle(m, bm)
            if v == "certified":
                for ga in range(m.ngeom):
                    for gb in range(ga + 1, m.ngeom):
                        if m.geom_bodyid[ga] == m.geom_bodyid[gb]:
                            continue
                        r_ = O.motion_min(orc, ga, gb, float(times[0]), float(times[-1]), n=80, refine=1)
                        if r_.upper < margin - 1e-9:
                            bad += 1
                            print(i, "FALSE-CERTIFIED", ga, gb, r_.upper, r_.time, modes)
            elif v == "violation" and c.witness is not None:
                w = c.witness
                ids = [mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, nm) for nm in w.geoms]
                a, b = orc.geoms(w.time, tuple(ids))
                ud = O.upper_distance(a, b)
                if not (O.check_witness(a, b, ud, 1e-9) and ud.upper < margin + 1e-6):
                    print(i, "WITNESS?", w.time, w.geoms, w.distance, ud.upper)
    print("summary", seed, nc, "oracle-bad", bad, file=sys.stderr)


if __name__ == "__main__":
    main(int(sys.argv[1]), int(sys.argv[2]), "--off" in sys.argv, "--oracle" in sys.argv)
