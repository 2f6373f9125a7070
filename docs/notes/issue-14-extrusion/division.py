import time, numpy as np
from monitor.certify.extrusion_null import warm_small_lp; warm_small_lp()  # what monitor.warmup should do
from scipy.spatial.transform import Rotation
from monitor.certify.extrusion import TranslatingBody, search_many
from monitor.bench.extrusion_scenes import agv_translating_bodies, WINDOW
from monitor.geometry.polytope import box_polytope, sphere_shape

def many_boxes(seed, n=10, per=3):
    rng = np.random.default_rng(seed)
    bodies = []
    for i in range(n):
        shapes, names = [], []
        for j in range(per):
            c = rng.uniform(-0.3, 0.3, 3)
            b = box_polytope(rng.uniform(0.05, 0.25, 3))
            # shift box by c: points/offsets
            from monitor.geometry.polytope import polytope_from_points
            shapes.append(polytope_from_points(b.points + c))
            names.append(f"b{i}g{j}")
        R = Rotation.random(random_state=int(rng.integers(1 << 31))).as_matrix()
        p0 = rng.uniform(-2, 2, 3); v = rng.normal(size=3) * 1.0
        if rng.random() < 0.3: v = np.zeros(3)
        t = np.array([0.0, 0.5, 1.0]); mid = p0 + 0.5 * v + rng.normal(size=3) * 0.2
        bodies.append(TranslatingBody(f"B{i}", tuple(shapes), tuple(names), R, t, np.stack([p0, mid, p0 + v])))
    return bodies

def run(bodies, win, margin, division, reps=3):
    ts = []
    for _ in range(reps):
        t = time.perf_counter()
        r = search_many(bodies, None, win, margin, division=division)
        ts.append(time.perf_counter() - t)
    return float(np.median(ts)), r

sets = [("agv straight skewed", agv_translating_bodies("straight", True), WINDOW),
        ("agv weaving skewed", agv_translating_bodies("weaving", True), WINDOW)]
sets += [(f"boxes seed {s}", many_boxes(s), (0.0, 1.0)) for s in range(6)]
tot = {"bisect": [0, 0, 0], "16way": [0, 0, 0]}
for name, bodies, win in sets:
    for margin in (0.0, 0.01):
        res = {}
        for div in ("bisect", "16way"):
            t, r = run(bodies, win, margin, div)
            res[div] = (t, r)
            tot[div][0] += t; tot[div][1] += r.stats["lps"] + r.stats["dual_shortcut"]; tot[div][2] += r.stats["regions"]
        a, b = res["bisect"][1], res["16way"][1]
        agree = all(x.verdict == y.verdict for x, y in zip(a.outcomes, b.outcomes))
        print(f"{name:22s} m={margin:<5} pairs={len(a.outcomes):4d} bisect {res['bisect'][0]*1e3:7.1f} ms lps {a.stats['lps']:3d}+{a.stats['dual_shortcut']:3d} regions {a.stats['regions']:4d} | 16way {res['16way'][0]*1e3:7.1f} ms lps {b.stats['lps']:3d}+{b.stats['dual_shortcut']:3d} regions {b.stats['regions']:4d} | agree {agree} | ratio {res['16way'][0]/res['bisect'][0]:.2f}")
print(tot)
