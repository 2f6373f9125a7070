import numpy as np, mujoco, monitor, sys
from monitor.certify.engine import certify
from monitor.certify.common import Budget
m = mujoco.MjModel.from_xml_path("models/arm/scene.xml")
scene = monitor.Scene.from_model(m)
rng = np.random.default_rng(int(sys.argv[1]))
N = int(sys.argv[2]); bad = []; counts = {}
class Slow(Budget):
    pass
for it in range(N):
    n = int(rng.integers(2, 6))
    q = np.repeat(m.qpos0[None], n, 0) + np.cumsum(rng.normal(0, 0.6, (n, m.nq)), 0) * (rng.random(m.nq) < 0.7)
    plan = monitor.Plan(np.linspace(0, 0.2, n), q, m)
    ref = {meth: certify(scene, plan, margin=0.0, epsilon=1e-3, method=meth) for meth in ("auto", "toleranced")}
    rv = {k: str(v.verdict) for k, v in ref.items()}
    if len(set(rv.values()) - {"uncertain"}) > 1: bad.append((it, "ref disagree", rv))
    for b in (Budget(tests=1), Budget(tests=7), Budget(tests=200), Budget(seconds=0.0), Budget(seconds=1e-4), Slow(seconds=1e-3), Slow(tests=5)):
        for meth in ("auto", "toleranced"):
            c = certify(scene, plan, margin=0.0, epsilon=1e-3, method=meth, budget=b)
            v = str(c.verdict); counts[(meth, v)] = counts.get((meth, v), 0) + 1
            if v != "uncertain" and v != rv[meth] and rv[meth] != "uncertain":
                bad.append((it, meth, repr(b)[:40], v, rv[meth]))
print(counts, "bad", bad[:6], len(bad))
