"""A/B of the bench's sparse row (monitor.bench.targets._measure_sparse's timing) between two trees.

Usage: python docs/notes/issue-12-sweep-2/ab_sparse.py BASE_TREE NEW_TREE [ROUNDS]
Each round runs one fresh process per tree (alternating which goes first); each process times,
per motion and size (10, 100, 1000, 3000), the FIRST certify on a fresh scene (as the bench does at
>= 1000 bodies) and the median of 5 later calls; prints the per-tree medians over rounds and the
fitted exponent over 10/100/1000 of the bench's figure (medians of 7 at 10 and 100, first call at 1000).
"""
import json
import os
import subprocess
import sys

import numpy as np

CHILD = r"""
import json, time, numpy as np, monitor
from monitor.bench.suites import scaling_scene
from monitor.certify.common import Budget
from monitor.certify.engine import certify
m3, b3 = scaling_scene(3, "sparse", "translating")
certify(monitor.Scene.from_model(m3, pairs="all"), b3, epsilon=1e-3)
out = {}
for motion in ("translating", "rotating"):
    for n in (10, 100, 1000, 3000):
        model, bm = scaling_scene(n, "sparse", motion)
        scene = monitor.Scene.from_model(model, pairs="all")
        ts = []
        for _ in range(1 if n >= 1000 else 7):
            t = time.perf_counter(); certify(scene, bm, epsilon=1e-3, budget=Budget(seconds=60.0))
            ts.append(time.perf_counter() - t)
        later = []
        for _ in range(5):
            t = time.perf_counter(); certify(scene, bm, epsilon=1e-3, budget=Budget(seconds=60.0))
            later.append(time.perf_counter() - t)
        out[f"{motion} {n}"] = (float(np.median(ts)), float(np.median(later)))
print("AB " + json.dumps(out))
"""

base, new = sys.argv[1], sys.argv[2]
rounds = int(sys.argv[3]) if len(sys.argv) > 3 else 3
res = {base: [], new: []}
for r in range(rounds):
    for tree in (base, new) if r % 2 == 0 else (new, base):
        env = dict(os.environ, PYTHONPATH=tree)
        p = subprocess.run([sys.executable, "-c", CHILD], env=env, capture_output=True, text=True, cwd=tree)
        line = [x for x in p.stdout.splitlines() if x.startswith("AB ")]
        if not line:
            sys.exit(p.stderr[-2000:])
        res[tree].append(json.loads(line[-1][3:]))
keys = list(res[base][0])
print("| motion, bodies | base first call (ms) | new first call (ms) | ratio "
      "| base later (ms) | new later (ms) | ratio |")
print("|---|---|---|---|---|---|---|")
for k in keys:
    f = [np.median([x[k][0] for x in res[t]]) * 1e3 for t in (base, new)]
    s = [np.median([x[k][1] for x in res[t]]) * 1e3 for t in (base, new)]
    print(f"| {k} | {f[0]:.3f} | {f[1]:.3f} | {f[1] / f[0]:.2f} "
          f"| {s[0]:.3f} | {s[1]:.3f} | {s[1] / s[0]:.2f} |")
for motion in ("translating", "rotating"):
    for t, name in ((base, "base"), (new, "new")):
        ys = [np.median([x[f"{motion} {n}"][0] for x in res[t]]) for n in (10, 100, 1000)]
        e = np.polyfit(np.log([10, 100, 1000]), np.log(ys), 1)[0]
        print(f"{motion} {name}: exponent over 10/100/1000 (bench figure) {e:.2f}; "
              f"slope 100->1000 {np.log10(ys[2] / ys[1]):.2f}")
