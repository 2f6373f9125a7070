import sys, time, numpy as np
from monitor.certify.extrusion_null import warm_small_lp; warm_small_lp()  # what monitor.warmup should do
sys.path.insert(0, "tests")
from test_extrusion_pipeline import seeded_translating_pairs
from monitor.certify.extrusion import check_pairs
from monitor.tolerances import DEFAULT
pairs = seeded_translating_pairs(11, 80)
ext = DEFAULT.extrusion_slack + DEFAULT.pad(0.0)
cfg = {"old (pairwise, exact swept)": dict(nary=False, offset=False), "pairwise + offset pipeline": dict(nary=False, offset=True),
       "nary + offset pipeline": dict(nary=True, offset=True), "nary, exact swept": dict(nary=True, offset=False)}
for c in cfg.values(): check_pairs(pairs[:3], (0.0, 1.0), ext, **c)
res = {k: [] for k in cfg}
for rep in range(5):
    for k, c in cfg.items():
        ts = []
        for p in pairs:
            t = time.perf_counter(); check_pairs([p], (0.0, 1.0), ext, **c); ts.append(time.perf_counter() - t)
        res[k].append(ts)
base = np.min(np.array(res["old (pairwise, exact swept)"]), axis=0)
for k in cfg:
    m = np.min(np.array(res[k]), axis=0)
    print(f"{k:32s} median per pair-window {np.median(m)*1e3:.2f} ms, median ratio to old {np.median(m / base):.2f}")
