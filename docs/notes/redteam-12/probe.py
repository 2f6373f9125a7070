import sys, json; sys.path.insert(0, "/tmp/rt12")
import gen, numpy as np, monitor
for seed, sel in ((264, 1), (462, 1)):
    for line in open("/tmp/rt12/base.jsonl"):
        r = json.loads(line)
        if r["seed"] == seed and len(r["sel"]) == sel and r["verdict"] == "violation" and r["method"] == "toleranced" and abs(r["margin"] - r["dmin"][0] - 1e-5) < 1e-9:
            break
    m, times, qpos, meta = gen.make_case(seed)
    pairs = gen.candidate_pairs(m)
    scene = monitor.Scene.from_model(m, pairs=pairs); plan = monitor.Plan(times, qpos, model=m)
    for eps in (1e-4, 1e-5, 1e-6):
        c = monitor.certify(scene, plan, margin=r["margin"], epsilon=eps, method="toleranced", window=tuple(r["win"]), pairs=[pairs[i] for i in r["sel"]])
        p = c.pairs[0]
        print(seed, eps, c.verdict, p.method, p.tests, p.max_depth, c.witness and c.witness.time, c.stats.get("budget_exhausted"))
