"""A/B of the bench's pair-window calls: per case median us (run_ours' call), verdict, earliest, witness.

Usage: python pwab.py OUT.json TREE_A[::patch] TREE_B[::patch] [rounds]
Each round runs every case in a fresh subprocess per tree (A, B alternated); per case the median CPU time
(time.process_time, robust to time-sharing) of 31 calls (3 for the slow screw / bezier / 1e-4 cases).
The answers (verdict, earliest time, witness time/point/distance, tests) are compared bit for bit.
"""
import json
import os
import subprocess
import sys

CHILD = r'''
import json, sys, time
import numpy as np
import monitor  # noqa: F401
from monitor.bench.cases import make_cases
from monitor.certify.common import Budget
from monitor.certify.engine import certify
import os
exec(os.environ.get("PWAB_PATCH", ""))   # e.g. switch one engine feature off (same tree, A/B by process)
out = {}
for c in make_cases(seed=7, quick=True):
    s, m = c.scene(16), c.body_motion()
    certify(s, m, margin=0.0, epsilon=1e-3, method="toleranced", budget=Budget(seconds=1.0))
    ts = []
    n = 31 if c.group in ("rotating", "translating") and "1e-04" not in c.name else 3
    for _ in range(n):
        b = Budget(seconds=1.0)
        t = time.process_time()
        cert = certify(s, m, margin=0.0, epsilon=1e-3, method="toleranced", budget=b)
        ts.append(time.process_time() - t)
    w = cert.witness
    out[c.name] = {"us": 1e6 * float(np.median(ts)), "verdict": str(cert.verdict),
                   "earliest": None if cert.earliest_time is None else repr(float(cert.earliest_time)),
                   "clear": repr(float(cert.clearance)), "tests": int(cert.stats.get("tests", -1)),
                   "witness": None if w is None else [repr(float(w.time)), [repr(float(x)) for x in w.point],
                                                       repr(float(w.distance)), list(w.geoms)],
                   "pair": [str(p.verdict) + "/" + str(p.method) for p in cert.pairs]}
print(json.dumps(out))
'''


def run(tree):
    tree, _, patch = tree.partition("::")      # TREE::python-snippet run in the child before the cases
    env = dict(os.environ, PYTHONPATH=tree, PWAB_PATCH=patch)
    r = subprocess.run([sys.executable, "-c", CHILD], env=env, capture_output=True, text=True, check=True)
    return json.loads(r.stdout.strip().splitlines()[-1])


def main():
    out, ta, tb = sys.argv[1], sys.argv[2], sys.argv[3]
    rounds = int(sys.argv[4]) if len(sys.argv) > 4 else 2
    res = {"A": [], "B": []}
    for _ in range(rounds):
        res["A"].append(run(ta))
        res["B"].append(run(tb))
    import numpy as np
    names = list(res["A"][0])
    diffs = []
    for n in names:
        a, b = res["A"][0][n], res["B"][0][n]
        for k in ("verdict", "earliest", "clear", "tests", "witness", "pair"):
            if a[k] != b[k]:
                diffs.append((n, k, a[k], b[k]))
    for lab in ("A", "B"):
        meds = [np.median([r[n]["us"] for n in names]) for r in res[lab]]
        print(lab, "median us per round:", " ".join(f"{m:.1f}" for m in meds))
    ratios = [np.median([res["B"][i][n]["us"] / res["A"][i][n]["us"] for n in names]) for i in range(rounds)]
    print("median per-case ratio B/A per round:", " ".join(f"{r:.3f}" for r in ratios))
    print("differences:", len(diffs))
    for d in diffs:
        print("  ", d)
    json.dump(res, open(out, "w"))


main()
