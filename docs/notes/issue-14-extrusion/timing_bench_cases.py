import sys, time, numpy as np
from monitor.certify.extrusion_null import warm_small_lp; warm_small_lp()  # what monitor.warmup should do
from monitor.bench.cases import make_cases
from monitor.certify.engine import certify
quick = "quick" in sys.argv
cases = [c for c in make_cases(seed=7, quick=quick) if c.group == "translating"]
rows = []
stages = {}
times = []
for c in cases:
    scene = c.scene()
    plan = c.body_motion()
    cert = certify(scene, plan, method="auto")
    ts = []
    for _ in range(5):
        t = time.perf_counter(); cert = certify(scene, plan, method="auto"); ts.append(time.perf_counter() - t)
    times.append(np.min(ts))
    st = cert.stats.get("extrusion_stages", {})
    for k, v in st.items():
        key = (cert.verdict, k)
        stages[key] = stages.get(key, 0) + v
    rows.append((c.name, cert.verdict, st, cert.stats["checker_mix"]))
for r in rows: print(*r)
print("stages", stages)
import json, os; json.dump(dict(zip([c.name for c in cases], times)), open(os.environ.get("H14A_OUT", "/dev/null"), "w"))
print("cases", len(cases), "median per pair-window ms %.2f" % (1e3 * np.median(times)), "mean %.2f" % (1e3 * np.mean(times)))
