"""First vs repeated certify on a fresh scaling scene (the bench times ONE call at >= 1000 bodies).

Usage: PYTHONPATH=<tree> python docs/notes/issue-12-sweep/first_call.py N [sparse|dense]
[translating|rotating]
"""
import sys
import time

import monitor
from monitor.bench.suites import scaling_scene

n = int(sys.argv[1])
density = sys.argv[2] if len(sys.argv) > 2 else "sparse"
motion = sys.argv[3] if len(sys.argv) > 3 else "translating"
model3, bm3 = scaling_scene(3, density, motion)
monitor.certify(monitor.Scene.from_model(model3, pairs="all"), bm3, epsilon=1e-3)   # kernels loaded
model, bm = scaling_scene(n, density, motion)
t = time.perf_counter()
scene = monitor.Scene.from_model(model, pairs="all")
t_scene = time.perf_counter() - t
ts = []
for _ in range(5):
    t = time.perf_counter()
    cert = monitor.certify(scene, bm, epsilon=1e-3)
    ts.append(time.perf_counter() - t)
print(f"{n} {density} {motion}: Scene.from_model {t_scene * 1e3:.1f} ms; certify calls (ms): "
      + ", ".join(f"{x * 1e3:.2f}" for x in ts) + f"; verdict {cert.verdict}")
