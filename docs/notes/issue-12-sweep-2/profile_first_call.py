"""Plain-timer breakdown of the bench's sparse row: Scene.from_model, the FIRST certify, steady state.

Usage: PYTHONPATH=<tree> python docs/notes/issue-12-sweep-2/profile_first_call.py N [translating|rotating]
Wraps module-level functions with perf_counter timers (no cProfile: it inflates small calls).
"""
import sys
import time
from collections import defaultdict

import monitor
import monitor.scene as SC
from monitor.bench.suites import scaling_scene
from monitor.certify import engine as E
from monitor.certify import kernels as K
from monitor.certify import packed as PK

T = defaultdict(float)


def wrap(mod, name, label=None):
    """Replace ``mod.name`` by a timed wrapper adding to ``T[label]``."""
    f = getattr(mod, name)
    label = label or f"{mod.__name__.split('.')[-1]}.{name}"

    def g(*a, **kw):
        t = time.perf_counter()
        try:
            return f(*a, **kw)
        finally:
            T[label] += time.perf_counter() - t
    setattr(mod, name, g)


n = int(sys.argv[1])
motion = sys.argv[2] if len(sys.argv) > 2 else "translating"
m3, b3 = scaling_scene(3, "sparse", motion)
monitor.certify(monitor.Scene.from_model(m3, pairs="all"), b3, epsilon=1e-3)   # kernels loaded
for mod, name in [(SC, "_filter_pairs"), (SC, "_drop_overlapping_world_children"), (SC, "_geom_shape"),
                  (SC, "_to_body"), (SC, "geom_frame"), (SC, "_Snapshot"),
                  (K, "scene_pack"), (PK, "pack_shapes"), (PK, "_curved_geoms"), (PK, "_content_key"),
                  (K, "trajectory_pack_memo"), (E, "_sweep_rows"), (E, "_select"), (E, "_plan_inputs"),
                  (E, "_check_model"),
                  (E, "_window_kernel"), (E, "_all_culled"), (E, "_fast_prep")]:
    wrap(mod, name)
model, bm = scaling_scene(n, "sparse", motion)
t = time.perf_counter()
scene = monitor.Scene.from_model(model, pairs="all")
T["Scene.from_model (total)"] = time.perf_counter() - t
print(f"{n} sparse {motion}: P = {len(scene.pair_ids)}, G = {len(scene.geoms)}")
for k in sorted(T, key=T.get, reverse=True):
    print(f"  from_model  {k:40s} {T[k] * 1e3:9.2f} ms")
T.clear()
from monitor.certify.common import Budget  # noqa: E402

ts = []
for i in range(6):
    t = time.perf_counter()
    monitor.certify(scene, bm, epsilon=1e-3, budget=Budget(seconds=60.0))
    ts.append(time.perf_counter() - t)
    if i == 0:
        first = dict(T)
        T.clear()
print("  certify calls (ms): " + ", ".join(f"{x * 1e3:.2f}" for x in ts))
for k in sorted(first, key=first.get, reverse=True):
    print(f"  first call  {k:40s} {first[k] * 1e3:9.2f} ms")
for k in sorted(T, key=T.get, reverse=True):
    print(f"  later (x5)  {k:40s} {T[k] / 5 * 1e3:9.2f} ms per call")
