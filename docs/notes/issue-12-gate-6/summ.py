"""Medians and pair ratios of ab_split.sh output (base lines start with BASE's path).

python docs/notes/issue-12-gate-6/summ.py AB_OUTPUT BASE_PATH
"""
import re, statistics as S, sys
from collections import defaultdict
D = defaultdict(lambda: defaultdict(list))
for line in open(sys.argv[1]):
    if "us gated" not in line:
        continue
    tree = "base" if line.startswith(sys.argv[2]) else "new"
    w = line.split()[1].rstrip(":")
    g = float(re.search(r"us gated (\d+) us", line).group(1))
    x = float(re.search(r"= ([\d.]+)x", line).group(1))
    parts = {k: float(v) for k, v in re.findall(r"(physics|certify|plan|gate|wrapper|env) (\d+) ", line)}
    D[w][tree].append((g, x, parts))
for w, d in D.items():
    b, n = d["base"], d["new"]
    pr = [nn[0] / bb[0] for bb, nn in zip(b, n)]
    print(f"{w}: gated us base {[int(v[0]) for v in b]} new {[int(v[0]) for v in n]}; pair ratios "
          f"{[round(r, 3) for r in pr]} median {S.median(pr):.3f}")
    print(f"   x (gated/ungated, same process) base {[v[1] for v in b]} new {[v[1] for v in n]}; medians "
          f"{S.median(v[1] for v in b):.2f} -> {S.median(v[1] for v in n):.2f}")
    print("   parts (medians, us): " + ", ".join(
        f"{k} {S.median(v[2][k] for v in b):.0f} -> {S.median(v[2][k] for v in n):.0f}" for k in b[0][2]))
