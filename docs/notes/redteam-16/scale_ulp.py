"""Red team 16, idea (1b): can FK rounding make the new scale smaller than the former one?

A static body far out (|P| ~ L) carries a child whose slide / hinge coordinate moves by a few
ulps of L (so the child's computed origin moves by whole ulps of L while its bound W is ~ the
true motion); every geom at its body's origin (rho = 0). Counts new < former.
Usage: PYTHONPATH=<tree> python scale_ulp.py N SEED
"""
import sys

import mujoco
import numpy as np

from monitor.motion.kernel import TOL_SCALE
from monitor.motion.pack import pack_trajectory
from monitor.motion.plan import Plan

sys.path.insert(0, __file__.rsplit("/", 1)[0])
from scale_fuzz import fmt, old_scale, rquat  # noqa: E402


def main(n, seed, verbose=False):
    rng = np.random.default_rng(seed)
    cnt = smaller = smaller_pk = below_origin = 0
    worst = (0.0, None)
    for i in range(n):
        L = 10.0 ** rng.uniform(3, 8.9)
        kind = rng.choice(["slide", "hinge"])
        P = rng.normal(size=3)
        P *= L / np.linalg.norm(P)
        arm = rng.uniform(0.5, 2.0)
        xml = (f'<mujoco><worldbody><body name="p" pos="{fmt(P)}" quat="{fmt(rquat(rng))}">'
               f'<geom type="sphere" size="0.1"/>'
               f'<body name="c" pos="{fmt(rng.normal(size=3) * arm)}">'
               f'<joint name="j" type="{kind}" axis="{fmt(rng.normal(size=3))}"/>'
               f'<geom type="sphere" size="0.1"/></body></body></worldbody></mujoco>')
        m = mujoco.MjModel.from_xml_string(xml)
        K = int(rng.integers(2, 30))
        ulp = np.spacing(L)
        q0 = rng.uniform(-1, 1) * (1.0 if kind == "hinge" else 1.0)
        # steps of 0.01 to 10 ulps of L (relative to the arm)
        q = q0 + np.cumsum(rng.uniform(-1, 1, K)) * ulp * 10.0 ** rng.uniform(-2, 1) / arm
        q[0] = q0
        times = np.cumsum(rng.uniform(0.01, 1.0, K))
        plan = Plan(times, q[:, None].copy(), model=m)
        if not plan.moving_bodies().any():
            continue
        new, old = plan._scale, old_scale(plan)
        pk = float(pack_trajectory(plan).tol[TOL_SCALE])
        cnt += 1
        dense = np.linspace(plan.t0, plan.t1, 64)
        pos_d, _ = plan.body_poses(np.concatenate([dense, plan.times]))
        reach = float(np.linalg.norm(pos_d, axis=-1).max())
        below_origin += reach > new
        if new < old:
            smaller += 1
            rel = (old - new) / old
            if rel > worst[0]:
                worst = (rel, (i, kind, L, new, old, old - new))
        smaller_pk += pk < old
        if verbose and (new < old or reach > new):
            print("case", i, kind, repr(P.tolist()), repr(xml), repr(times.tolist()), repr(q.tolist()))
    print(f"seed {seed}: moving plans {cnt}, Plan._scale < former: {smaller}, pack tol[3] < former: {smaller_pk}, "
          f"S below an FK origin (dense + waypoints): {below_origin}, worst {worst}")


if __name__ == "__main__":
    main(int(sys.argv[1]), int(sys.argv[2]), "-v" in sys.argv)
