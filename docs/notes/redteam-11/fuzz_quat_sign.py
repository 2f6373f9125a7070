import numpy as np, mujoco, monitor, sys
from monitor.certify.engine import certify
XML = """<mujoco><worldbody>
  <geom name="wall" type="box" size="0.05 0.5 0.5" pos="0.6 0 0.5"/>
  <body name="cart" pos="0 0 0.5"><freejoint/><geom name="box" type="box" size="0.1 0.1 0.1"/></body>
</worldbody></mujoco>"""
m = mujoco.MjModel.from_xml_string(XML)
scene = monitor.Scene.from_model(m, pairs="all", allowed=None)
rng = np.random.default_rng(int(sys.argv[1]) if len(sys.argv) > 1 else 0)
bad = []; counts = {}
N = int(sys.argv[2]) if len(sys.argv) > 2 else 200
for it in range(N):
    n = int(rng.integers(2, 6))
    x = np.sort(rng.uniform(-0.2, 0.5, n)) if rng.random() < 0.5 else rng.uniform(0.2, 0.46, n)
    q = np.zeros((n, 7)); q[:, 0] = x; q[:, 2] = 0.0  # body pos is relative: body at z 0.5 + qpos? freejoint qpos absolute
    q[:, 2] = 0.5
    signs = rng.choice([-1.0, 1.0], n); q[:, 3] = signs
    plan = monitor.Plan(np.linspace(0, 0.1, n), q, m)
    # closed form: gap along x between box (half 0.1) and wall face at 0.55, on piecewise-linear x
    xs = np.concatenate([np.linspace(x[i], x[i + 1], 200) for i in range(n - 1)])
    gap = 0.55 - (xs.max() + 0.1)
    res = {}
    for meth in ("auto", "toleranced", "extrusion"):
        try:
            c = certify(scene, plan, margin=0.0, epsilon=1e-3, method=meth)
            res[meth] = str(c.verdict)
        except monitor.errors.InvalidInputError:
            res[meth] = "refused"; counts[(meth, "refused", bool(np.all(signs == signs[0])))] = counts.get((meth, "refused", bool(np.all(signs == signs[0]))), 0) + 1; continue
        key = (meth, res[meth]); counts[key] = counts.get(key, 0) + 1
        if res[meth] == "certified" and gap <= 0: bad.append((it, meth, "certified but gap", gap))
        if res[meth] == "violation" and gap > 1e-9: bad.append((it, meth, "violation but gap", gap))
    if len({v for v in res.values()} - {"uncertain", "refused"}) > 1: bad.append((it, "disagree", res, gap))
print("counts", sorted(counts.items())); print("bad", bad[:10], len(bad))
