import time, numpy as np
from scipy.optimize import linprog
from monitor.certify.extrusion_null import small_slack_lp
rng = np.random.default_rng(1)
bad = none = 0; tf = ts = 0.0
from monitor.certify.extrusion_null import warm_small_lp
warm_small_lp()
for trial in range(400):
    m = int(rng.integers(8, 40))
    G = rng.normal(size=(m, 4)); G[:, :3] /= np.linalg.norm(G[:, :3], axis=1, keepdims=True)
    h = rng.uniform(-0.5, 1, m)
    lo = -rng.uniform(0.1, 2, 4); hi = rng.uniform(0.1, 2, 4)
    if trial % 3 == 0: lo[3] = 0.0
    t = time.perf_counter(); f = small_slack_lp(G, h, lo, hi); tf += time.perf_counter() - t
    t = time.perf_counter()
    r = linprog(np.array([0, 0, 0, 0, -1.0]), A_ub=np.hstack([G, np.ones((m, 1))]), b_ub=h,
                bounds=[(lo[k], hi[k]) for k in range(4)] + [(None, None)], method="highs-ds")
    ts += time.perf_counter() - t
    if f is None: none += 1; continue
    z, s, y = f
    if abs(s - (-r.fun)) > 1e-9 * (1 + abs(r.fun)): bad += 1; print(trial, s, -r.fun)
print("mismatch", bad, "none", none, "fast ms %.3f scipy ms %.3f" % (tf / 400 * 1e3, ts / 400 * 1e3))
