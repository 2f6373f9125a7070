"""Red team 16, ideas (3)/(4): the one-call path and the first witness candidate, on Plans.

Random scenes: static boxes / capsules / spheres, 1-3 moving bodies on slide joints (some with a
hinge or a free joint whose rotation changes by 1e-300 rad, by -0.0 only, by the sign bit of a
quaternion component, or by a whole sign flip of the quaternion), windows with t0 = -0.0, huge
times, sub-windows, test budgets, every method and both ongoing modes.

Prints one line per certify call: "<case> <key>" (key = to_dict() without wall time), so that two
trees / two flag settings can be diffed. With --oracle, every certified call is checked with
tests/redteam_oracle.py (dense sampling, verified witnesses) and every violation witness is
re-checked at its time.
Usage: PYTHONPATH=<tree> python onecall_fuzz.py N SEED [--off] [--oracle]
"""
import sys

import mujoco
import numpy as np

import monitor
from monitor.certify import engine

sys.path.insert(0, "/work/wt/rt16/tests")
import redteam_oracle as O  # noqa: E402


def fmt(v):
    return " ".join(f"{x:.17g}" for x in np.atleast_1d(v))


STATIC = ((0.05, 0.3), (0.03, 0.2), (0.05, 0.3))     # size ranges (box, capsule, sphere) of static shapes
MOVING = ((0.03, 0.15), (0.02, 0.1), (0.03, 0.15))   # and of moving ones


def random_shape(rng, ranges):
    """(kind, size, unit quaternion): the draws in a fixed order (every size range is drawn)."""
    kind = rng.choice(["box", "capsule", "sphere"])
    size = {"box": rng.uniform(*ranges[0], 3), "capsule": rng.uniform(*ranges[1], 2),
            "sphere": rng.uniform(*ranges[2], 1)}[kind]
    q = rng.normal(size=4)
    return kind, size, q / np.linalg.norm(q)


def static_lines(rng):
    """The MJCF opening and 1-3 random static world geoms (s0, s1, ...), as a list of lines."""
    lines = ['<mujoco><option><flag contact="disable"/></option><worldbody>']
    for i in range(int(rng.integers(1, 4))):
        kind, size, q = random_shape(rng, STATIC)
        lines.append(f'<geom name="s{i}" type="{kind}" size="{fmt(size)}" pos="{fmt(rng.uniform(-0.6, 0.6, 3))}" '
                     f'quat="{fmt(q)}"/>')
    return lines


def make(rng):
    lines = static_lines(rng)
    rot_modes = []
    nb = int(rng.integers(1, 4))
    for b in range(nb):
        kind, size, q = random_shape(rng, MOVING)
        free = rng.random() < 0.3
        lines.append(f'<body name="b{b}" pos="{fmt(rng.uniform(-0.1, 0.1, 3))}">')
        if free:
            lines.append(f'<freejoint name="f{b}"/>')
            rot_modes.append(("free", rng.choice(["none", "signbit", "flip", "tiny", "normal"])))
        else:
            for ax in ("1 0 0", "0 1 0", "0 0 1"):
                lines.append(f'<joint type="slide" axis="{ax}"/>')
            if rng.random() < 0.5:
                lines.append(f'<joint type="hinge" axis="{fmt(rng.normal(size=3))}"/>')
                rot_modes.append(("hinge", rng.choice(["none", "negzero", "tiny", "ulp", "normal"])))
            else:
                rot_modes.append(("slide", "none"))
        lines.append(f'<geom name="g{b}" type="{kind}" size="{fmt(size)}" pos="{fmt(rng.uniform(-0.05, 0.05, 3))}" '
                     f'quat="{fmt(q)}"/></body>')
    lines.append("</worldbody></mujoco>")
    return "\n".join(lines), rot_modes


def qpos_for(rng, m, rot_modes, K):
    q = np.tile(m.qpos0.copy(), (K, 1))
    jb = 0
    for b, (kind, mode) in enumerate(rot_modes):
        bid = b + 1
        a = m.jnt_qposadr[m.body_jntadr[bid]]
        p = np.cumsum(rng.uniform(-0.25, 0.25, (K, 3)), axis=0) + rng.uniform(-0.5, 0.5, 3)
        if rng.random() < 0.3:
            p[:, int(rng.integers(0, 3))] = p[0, 0]           # one coordinate frozen
        q[:, a:a + 3] = p
        if kind == "hinge":
            h = a + 3
            if mode == "none":
                q[:, h] = 0.7
            elif mode == "negzero":
                q[:, h] = np.where(np.arange(K) % 2 == 0, 0.0, -0.0)
            elif mode == "tiny":
                q[:, h] = np.where(np.arange(K) % 2 == 0, 0.0, 1e-300)
            elif mode == "ulp":
                q[:, h] = np.where(np.arange(K) % 2 == 0, 1.0, np.nextafter(1.0, 2.0))
            else:
                q[:, h] = rng.uniform(-2, 2, K)
        elif kind == "free":
            u = rng.normal(size=4)
            u /= np.linalg.norm(u)
            Q = np.tile(u, (K, 1))
            if mode == "none":
                Q[:] = [1.0, 0.0, 0.0, 0.0]
            elif mode == "signbit":
                Q[:] = [1.0, 0.0, 0.0, 0.0]
                Q[1::2, 1] = -0.0
            elif mode == "flip":
                Q[1::2] = -u
            elif mode == "tiny":
                Q[1::2, 1] = np.nextafter(Q[1::2, 1], 2.0)
            else:
                Q = rng.normal(size=(K, 4))
                Q /= np.linalg.norm(Q, axis=1, keepdims=True)
            q[:, a + 3:a + 7] = Q
        jb += 1
    return q


def settings(rng):
    """(margin m, method, ongoing) drawn in a fixed order."""
    margin = float(rng.choice([0.0, 0.001, 0.02]))
    meth = str(rng.choice(["auto", "auto", "extrusion", "toleranced"]))
    og = str(rng.choice(["violation", "deepen"]))
    return margin, meth, og


def certify_and_print(i, scene, traj, margin, meth, og, kw, counts):
    """Certify, print "<i> <to_dict() without wall time>" (or the typed error), count the verdict;
    the certificate or None."""
    try:
        c = monitor.certify(scene, traj, margin=margin, epsilon=1e-3, method=meth, ongoing=og, **kw)
    except Exception as e:   # noqa: BLE001
        print(i, "error", type(e).__name__, str(e)[:120])
        return None
    d = c.to_dict()
    d["stats"].pop("wall_seconds", None)
    print(i, repr(d))
    counts[c.verdict.value] = counts.get(c.verdict.value, 0) + 1
    return c


def oracle_check(i, m, c, orc, w0, w1, margin):
    """Problems (printed) of certificate ``c`` against the dense-sampling oracle ``orc`` on [w0, w1]:
    a certified call with a pair the oracle proves closer than ``margin`` or closer than the pair's
    claimed clearance; a violation witness that is not a verified contact below margin at its time."""
    bad = 0
    v = c.verdict.value
    if v == "certified":
        claimed = {tuple(p.geoms): p.clearance for p in c.pairs}
        for ga in range(m.ngeom):
            for gb in range(ga + 1, m.ngeom):
                if m.geom_bodyid[ga] == m.geom_bodyid[gb]:
                    continue
                r_ = O.motion_min(orc, ga, gb, w0, w1, n=80, refine=1)
                if r_.upper < margin - 1e-9:
                    bad += 1
                    print(i, "FALSE-CERTIFIED", ga, gb, r_.upper, r_.time)
                names = (mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_GEOM, ga),
                         mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_GEOM, gb))
                cl = claimed.get(names, claimed.get(names[::-1]))
                if cl is not None and cl > r_.upper + 1e-9:
                    bad += 1
                    print(i, "CLEARANCE-ABOVE-ORACLE", names, cl, r_.upper, r_.time)
    elif v == "violation" and c.witness is not None:
        w = c.witness
        ids = [mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, nm) for nm in w.geoms]
        a, b = orc.geoms(w.time, tuple(ids))
        ud = O.upper_distance(a, b)
        if not (O.check_witness(a, b, ud, 1e-9) and ud.upper < margin + 1e-6):
            bad += 1
            print(i, "WITNESS?", w.time, w.geoms, w.distance, ud.upper)
    return bad


def main(n, seed, off=False, oracle=False):
    if off:
        engine._ONE_CALL = False
    rng = np.random.default_rng(seed)
    bad = 0
    nc = {"certified": 0, "violation": 0, "uncertain": 0}
    for i in range(n):
        xml, modes = make(rng)
        m = mujoco.MjModel.from_xml_string(xml)
        K = int(rng.integers(2, 8))
        base = rng.choice([0.0, -0.0, 1e6, 1e15, 3.0])
        dt = rng.uniform(0.05, 1.0, K) * (1.0 if base < 1e14 else 1.0)
        times = base + np.concatenate([[0.0], np.cumsum(dt[1:])]) if base < 1e14 else \
            base + np.arange(K) * 0.25 * (1 + int(rng.integers(0, 4)))
        if base == 0.0 and np.copysign(1, base) < 0:
            times[0] = -0.0
        qpos = qpos_for(rng, m, modes, K)
        try:
            plan = monitor.Plan(times, qpos, model=m)
        except Exception as e:   # noqa: BLE001
            print(i, "plan-error", type(e).__name__, str(e)[:80])
            continue
        scene = monitor.Scene.from_model(m, pairs="all")
        margin, meth, og = settings(rng)
        kw = {}
        r = rng.random()
        if r < 0.15:
            kw["budget"] = {"tests": int(rng.integers(0, 40))}
        if rng.random() < 0.3:
            a = float(times[0] + rng.uniform(0, 0.5) * (times[-1] - times[0]))
            kw["window"] = (a, float(times[-1]))
        if rng.random() < 0.05:
            kw["window"] = (float(times[1]), float(times[1]))      # zero-length window
        c = certify_and_print(i, scene, plan, margin, meth, og, kw, nc)
        if c is None:
            continue
        if oracle and og == "violation":
            w0, w1 = kw.get("window", (float(times[0]), float(times[-1])))
            bad += oracle_check(i, m, c, O.PlanOracle(m, times, qpos), w0, w1, margin)
    print("summary", seed, nc, "oracle-bad", bad, file=sys.stderr)


if __name__ == "__main__":
    main(int(sys.argv[1]), int(sys.argv[2]), "--off" in sys.argv, "--oracle" in sys.argv)
