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
from onecall_fuzz import (MOVING, certify_and_print, fmt, oracle_check, random_shape, settings,  # noqa: E402
                         static_lines)


def make(rng):
    lines = static_lines(rng)
    nb = int(rng.integers(1, 4))
    for b in range(nb):
        kind, size, q = random_shape(rng, MOVING)
        lines.append(f'<body name="b{b}" mocap="true"><geom name="g{b}" type="{kind}" size="{fmt(size)}" '
                     f'pos="{fmt(rng.uniform(-0.05, 0.05, 3))}" quat="{fmt(q)}"/></body>')
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
        margin, meth, og = settings(rng)
        c = certify_and_print(i, scene, bm, margin, meth, og, {}, nc)
        if c is None:
            continue
        if oracle and og == "violation":
            bad += oracle_check(i, m, c, O.TrajectoryOracle(m, bm), float(times[0]), float(times[-1]), margin)
    print("summary", seed, nc, "oracle-bad", bad, file=sys.stderr)


if __name__ == "__main__":
    main(int(sys.argv[1]), int(sys.argv[2]), "--off" in sys.argv, "--oracle" in sys.argv)
