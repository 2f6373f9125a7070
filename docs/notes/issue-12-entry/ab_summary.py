"""Medians over runs of ab.sh output: python ab_summary.py ab.txt"""
import collections
import json
import statistics as st
import sys

rows = collections.defaultdict(lambda: collections.defaultdict(list))
for line in open(sys.argv[1]):
    tree, js = line.split(" ", 1)
    tree = "new" if tree.rstrip("/").endswith("h12r") else "old"
    for case, v in json.loads(js).items():
        for k in ("total_us", "kernel_us", "python_us"):
            rows[case][(tree, k)].append(v[k])
for case, d in rows.items():
    print(case, "  ".join(f"{t}:{k[:-3]}={st.median(v):.1f}" for (t, k), v in sorted(d.items())))
