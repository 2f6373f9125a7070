import time, monitor
from monitor.bench.suites import scaling_scene
from monitor.certify.engine import certify
from monitor.certify.common import Budget
for n in (10, 1000, 1000, 1000):
    model, bm = scaling_scene(n, "sparse", "rotating")
    scene = monitor.Scene.from_model(model, pairs="all")
    t = time.perf_counter(); certify(scene, bm, epsilon=1e-3, budget=Budget(seconds=60.0)); a = time.perf_counter() - t
    t = time.perf_counter(); certify(scene, bm, epsilon=1e-3, budget=Budget(seconds=60.0)); b = time.perf_counter() - t
    print(n, f"first {a*1e3:.1f} ms, again {b*1e3:.1f} ms")
