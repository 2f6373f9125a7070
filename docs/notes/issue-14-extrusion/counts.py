import sys
from monitor.certify.extrusion_null import warm_small_lp; warm_small_lp()  # what monitor.warmup should do
sys.path.insert(0, "tests")
from test_extrusion_pipeline import seeded_translating_pairs
from monitor.certify.extrusion import check_pairs, search_summary
from monitor.tolerances import DEFAULT
for seed, n in ((11, 80), (12, 100)):
    for margin in (0.0, 0.01):
        pairs = seeded_translating_pairs(seed, n)
        ext = margin + DEFAULT.extrusion_slack + DEFAULT.pad(margin)
        outs = check_pairs(pairs, (0.0, 1.0), ext, nary=True)
        tab = {}
        for o in outs:
            tab[(o.verdict, o.info["stage"])] = tab.get((o.verdict, o.info["stage"]), 0) + 1
        s = search_summary(outs)
        print(f"seed {seed} n {n} margin {margin}: {dict(sorted(tab.items()))}; LPs {s['lps']}, dual 1/2-row {s['dual_shortcut']}, offset LPs {s['offset_lps']}, offset certified {s['offset_certified']}, left open {s['offset_open']}")
