"""Summarise ab.sh output: per workload, medians of base and new, and per-pair new/base ratios.

Usage: python docs/notes/issue-12-gatechecks/summ.py out.jsonl BASE_TREE
"""
import json
import statistics
import sys

rows = [json.loads(x) for x in open(sys.argv[1]) if x.startswith("{")]
base = sys.argv[2].rstrip("/")
b = [r for r in rows if r["tree"].rstrip("/") == base]
n = [r for r in rows if r["tree"].rstrip("/") != base]
print(f"{len(b)} base and {len(n)} new processes")
for w in ("pusher", "arm", "tunnel", "hand30"):
    gb, gn = [r[w]["gated_us"] for r in b], [r[w]["gated_us"] for r in n]
    rb, rn = [r[w]["ratio"] for r in b], [r[w]["ratio"] for r in n]
    pr = [y / x for x, y in zip(gb, gn)]
    rr = [y / x for x, y in zip(rb, rn)]
    print(f"{w:7s} gated µs median base {statistics.median(gb):7.1f} new {statistics.median(gn):7.1f}; "
          f"per-pair new/base gated median {statistics.median(pr):.3f} (range {min(pr):.3f}-{max(pr):.3f}, "
          f"new faster in {sum(x < 1 for x in pr)}/{len(pr)}); x ungated base {statistics.median(rb):.2f} "
          f"new {statistics.median(rn):.2f}, per-pair ratio of ratios median {statistics.median(rr):.3f}")
