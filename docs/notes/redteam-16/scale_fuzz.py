"""Red team 16, idea (1): the new rounding scale against the former one, plan by plan.

new  = Plan._scale (and the compiled pack's tol[3])
old  = max_{k,b} |FK origin at waypoint k| + 3 max_b |ref_b| + max_b W_b   (W at scale 0)
Counts plans where new < old (any amount) and the worst relative deficit.
Usage: PYTHONPATH=<tree> python scale_fuzz.py N SEED
"""
import sys

import mujoco
import numpy as np

from monitor.motion.kernel import TOL_SCALE
from monitor.motion.pack import pack_trajectory
from monitor.motion.plan import Plan


def fmt(v):
    return " ".join(f"{x:.17g}" for x in v)


def rquat(rng):
    q = rng.normal(size=4)
    return q / np.linalg.norm(q)


def chain_xml(rng, big):
    """a random tree; geoms at body origins (rho = 0) half of the time; offsets up to `big`."""
    centred = rng.random() < 0.5
    nid = [0]

    def body(depth, top):
        nid[0] += 1
        n = f"b{nid[0]}"
        off = rng.uniform(-1, 1, 3) * (big if rng.random() < 0.5 else 1.0)
        mocap = top and rng.random() < 0.1
        s = [f'<body name="{n}" pos="{fmt(off)}" quat="{fmt(rquat(rng))}"' + (' mocap="true">' if mocap else '>')]
        if not mocap:
            if top and rng.random() < 0.3:
                s.append(f'<freejoint name="j{n}"/>')
            else:
                ball = False
                for k in range(rng.integers(1, 3)):
                    kind = "slide" if ball else rng.choice(["hinge", "slide", "ball", "hinge"])
                    ball = ball or kind == "ball"
                    jp = np.zeros(3) if centred else rng.uniform(-0.3, 0.3, 3)
                    ax = "" if kind == "ball" else f' axis="{fmt(rng.normal(size=3))}"'
                    s.append(f'<joint name="j{n}_{k}" type="{kind}" pos="{fmt(jp)}"{ax}/>')
        gp = np.zeros(3) if centred else rng.uniform(-0.4, 0.4, 3)
        s.append(f'<geom type="sphere" size="0.1" pos="{fmt(gp)}"/>')
        if depth > 0:
            s += body(depth - 1, False)
        s.append("</body>")
        return s

    lines = ['<mujoco><option><flag contact="disable"/></option><worldbody>']
    for _ in range(rng.integers(1, 3)):
        lines += body(int(rng.integers(0, 4)), True)
    lines.append("</worldbody></mujoco>")
    return "\n".join(lines)


def rqpos(rng, m, K, tiny):
    q = np.tile(np.array(m.qpos0), (K, 1))
    for j in range(m.njnt):
        a, typ = m.jnt_qposadr[j], m.jnt_type[j]
        for k in range(K):
            if typ == 0:
                q[k, a:a + 3] = rng.uniform(-1, 1, 3) * (1e6 if rng.random() < 0.3 else 1)
                q[k, a + 3:a + 7] = rquat(rng)
            elif typ == 1:
                q[k, a:a + 4] = rquat(rng)
            elif typ == 3:
                q[k, a] = rng.uniform(-4, 4)
            else:
                q[k, a] = rng.uniform(-0.5, 0.5)
    if tiny:   # tiny steps around the first waypoint: angles of ~eps
        d = 10.0 ** rng.uniform(-300, -6)
        for k in range(1, K):
            q[k] = q[0] + d * (q[k] - q[0])
            for j in range(m.njnt):
                typ = m.jnt_type[j]
                if typ in (0, 1):
                    a = m.jnt_qposadr[j] + (3 if typ == 0 else 0)
                    q[k, a:a + 4] /= np.linalg.norm(q[k, a:a + 4])
    return q


def old_scale(plan):
    wp = plan._wp_pos
    whole = plan._bounds(plan._times[:1].copy(), plan._times[-1:].copy(), scale=0.0,
                         kinds=Plan._bound_kinds)[0][0]
    return (float(np.max(np.linalg.norm(wp, axis=-1), initial=0.0)) + plan._st.ref_norm
            + float(np.max(whole, initial=0.0)) + 2.0 * plan._st.ref_norm)


def main(n, seed):
    rng = np.random.default_rng(seed)
    tried = smaller = smaller_pack = errors = 0
    worst = (0.0, None)
    for i in range(n):
        big = 10.0 ** rng.uniform(0, 8.95)
        try:
            m = mujoco.MjModel.from_xml_string(chain_xml(rng, big))
        except Exception:
            continue
        K = int(rng.integers(2, 40))
        t0 = rng.choice([0.0, -0.0, 1e9, 1e15, rng.uniform(-10, 10)])
        times = t0 + np.cumsum(rng.uniform(0.001, 1.0, K))
        qpos = rqpos(rng, m, K, tiny=rng.random() < 0.5)
        mp_ = rng.uniform(-big, big, (m.nmocap, 3)) if m.nmocap else None
        mq_ = np.array([rquat(rng) for _ in range(m.nmocap)]) if m.nmocap else None
        try:
            plan = Plan(times, qpos, model=m, mocap_pos=mp_, mocap_quat=mq_)
            new = plan._scale
            pk = float(pack_trajectory(plan).tol[TOL_SCALE])
        except Exception as e:  # noqa: BLE001
            errors += 1
            print("error", i, type(e).__name__, e)
            continue
        old = old_scale(plan)
        tried += 1
        if not plan.moving_bodies().any():
            continue
        if new < old:
            smaller += 1
            rel = (old - new) / old
            if rel > worst[0]:
                worst = (rel, (i, new, old, big))
        if pk < old:
            smaller_pack += 1
    print(f"seed {seed}: plans {tried}, Plan._scale < former: {smaller}, pack tol[3] < former: {smaller_pack}, "
          f"errors {errors}, worst relative deficit {worst}")


if __name__ == "__main__":
    main(int(sys.argv[1]), int(sys.argv[2]))
