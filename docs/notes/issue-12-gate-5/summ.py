"""Summarise ab.sh output: per row, the gated/ungated ratio of each process and the pair ratio new/base.

usage: python summ.py AB_OUTPUT BASE_TREE
"""
import collections
import json
import statistics
import sys

base = sys.argv[2]
runs = collections.defaultdict(dict)  # (row, pair) -> {"base"|"new": record}
for line in open(sys.argv[1]):
    if "{" not in line:
        continue
    pair, rec = line.split(" ", 1)
    r = json.loads(rec)
    runs[(r["row"], int(pair))]["base" if r["tree"] == base else "new"] = r
rows = sorted({k[0] for k in runs}, key=lambda x: list(dict.fromkeys(k[0] for k in runs)).index(x))
for row in rows:
    b = [runs[k]["base"] for k in sorted(runs) if k[0] == row and "base" in runs[k] and "new" in runs[k]]
    n = [runs[k]["new"] for k in sorted(runs) if k[0] == row and "base" in runs[k] and "new" in runs[k]]
    pr = [y["ratio"] / x["ratio"] for x, y in zip(b, n)]
    pg = [y["gated_us"] / x["gated_us"] for x, y in zip(b, n)]
    def js(xs, fmt="{:.1f}"):
        return " / ".join(fmt.format(x) for x in xs)

    rb, rn = [x["ratio"] for x in b], [x["ratio"] for x in n]
    gb, gn = [x["gated_us"] for x in b], [x["gated_us"] for x in n]
    same = all(x["verdicts"] == y["verdicts"] for x, y in zip(b, n))
    print(f"{row:12s} base {js(rb)}x (median {statistics.median(rb):.1f}x) | new {js(rn)}x "
          f"(median {statistics.median(rn):.1f}x) | pair ratios {js(pr, '{:.2f}')} (median {statistics.median(pr):.2f}); "
          f"gated us median {statistics.median(gb):.0f} -> {statistics.median(gn):.0f} (pair median "
          f"{statistics.median(pg):.2f}); same verdicts: {same}")
