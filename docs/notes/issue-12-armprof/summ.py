"""Medians of an ab.sh output: gated µs, ungated µs, gated/ungated ratio per tree, and new/base per pair.

Usage: python docs/notes/issue-12-armprof/summ.py OUT.txt
"""
import json
import statistics
import sys

rows = {"base": [], "new": []}
for line in open(sys.argv[1]):
    who, _, js = line.partition(" ")
    if js.strip().startswith("{"):
        rows[who].append(json.loads(js))
for who, rs in rows.items():
    print(f"{who}: n={len(rs)} gated median {statistics.median(r['gated_us'] for r in rs):.1f} µs, ungated "
          f"{statistics.median(r['ungated_us'] for r in rs):.1f} µs, ratio median "
          f"{statistics.median(r['ratio'] for r in rs):.2f}x; gated {sorted(round(r['gated_us']) for r in rs)}")
pairs = list(zip(rows["base"], rows["new"]))
g = [n["gated_us"] / b["gated_us"] for b, n in pairs]
r = [n["ratio"] / b["ratio"] for b, n in pairs]
print(f"new/base gated per pair: median {statistics.median(g):.3f} {sorted(round(x, 3) for x in g)}")
print(f"new/base ratio per pair: median {statistics.median(r):.3f}; new faster in {sum(x < 1 for x in g)}/{len(g)} pairs")
print("verdicts equal:", all(b["verdicts"] == n["verdicts"] for b, n in pairs))
