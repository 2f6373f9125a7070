"""Summarise ab_steps.sh output: per variant the gated us and ratio, base vs new, and the pair ratios.

python summ.py FILE
"""
import json, sys
import numpy as np
rows = []
for line in open(sys.argv[1]):
    if "RATIOS" not in line:
        continue
    tag, i = line.split()[:2]
    rows.append((tag, int(i), json.loads(line.split("RATIOS", 1)[1])))
work = rows[0][2]["work"]
for v in rows[0][2]["variants"]:
    b = {i: r["variants"][v] for t, i, r in rows if t == "base"}
    n = {i: r["variants"][v] for t, i, r in rows if t == "new"}
    ks = sorted(set(b) & set(n))
    pr = [n[k]["gated_us"] / b[k]["gated_us"] for k in ks]
    print(f"{work} {v}: gated us base {[round(b[k]['gated_us']) for k in ks]} new {[round(n[k]['gated_us']) for k in ks]}"
          f" | x ungated base {[round(b[k]['ratio'], 1) for k in ks]} new {[round(n[k]['ratio'], 1) for k in ks]}"
          f" | pair new/base {[round(x, 3) for x in pr]} median {np.median(pr):.3f}"
          f" | ratio medians {np.median([b[k]['ratio'] for k in ks]):.1f} -> {np.median([n[k]['ratio'] for k in ks]):.1f}")
