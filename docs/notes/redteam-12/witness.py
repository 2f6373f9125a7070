import json, sys, collections
sys.path.insert(0, "/tmp/rt12")
import gen, numpy as np
cache = {}
bad = 0; n = 0; worst = -1e9
for line in open(sys.argv[1]):
    r = json.loads(line)
    if r.get("verdict") != "violation" or r.get("witness") is None: continue
    seed = r["seed"]
    if seed not in cache:
        m, times, qpos, meta = gen.make_case(seed)
        cache.clear(); cache[seed] = (m, times, qpos, gen.Oracle(m, times, qpos), gen.geom_names(m))
    m, times, qpos, orc, names = cache[seed]
    t, geoms = r["witness"]
    d = orc.at(t, [(names.index(geoms[0]), names.index(geoms[1]))])[0]
    n += 1
    worst = max(worst, d - r["margin"])
    if d >= r["margin"] + 1e-9:
        bad += 1; print("BAD witness", seed, r["method"], r["margin"], t, geoms, d)
print("witnesses", n, "bad", bad, "max d-margin", worst)
