"""Summarise ab.sh output: per workload, median gated µs per side and per-pair new/base ratios.

Usage: python docs/notes/issue-12-gatepath/summ.py OUT
"""
import json
import statistics
import sys

rows: dict[int, dict[str, dict]] = {}
for line in open(sys.argv[1]):
    side, i, js = line.split(" ", 2)
    if js.strip():
        rows.setdefault(int(i), {})[side] = json.loads(js)
pairs = [r for r in rows.values() if "base" in r and "new" in r]
for key in ("tunnel", "arm", "pusher", "hand30"):
    b = [p["base"][key]["gated_us"] for p in pairs]
    n = [p["new"][key]["gated_us"] for p in pairs]
    rat = [y / x for x, y in zip(b, n)]
    rb = [p["base"][key]["ratio"] for p in pairs]
    rn = [p["new"][key]["ratio"] for p in pairs]
    print(f"{key:7s} {len(pairs)} pairs: gated base median {statistics.median(b):8.1f} µs, new {statistics.median(n):8.1f} µs; "
          f"new/base per pair median {statistics.median(rat):.3f} (range {min(rat):.3f}-{max(rat):.3f}, "
          f"new faster in {sum(x < 1 for x in rat)}/{len(rat)}); x ungated base {statistics.median(rb):.1f} -> new "
          f"{statistics.median(rn):.1f}")
