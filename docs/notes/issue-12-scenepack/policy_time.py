"""Scene.from_model with a pair policy (hazards=, allow=, an explicit ACM) on the sparse scaling scenes.

Usage (cwd = <tree>): PYTHONPATH=<tree> python docs/notes/issue-12-scenepack/policy_time.py N [N ...]
Prints per N the seconds of one from_model(pairs="all") without and with the policy (after a warm-up).
"""
import sys
import time

import monitor
from monitor.bench.suites import scaling_scene

policy = {"hazards": ["g1*", "g2*"], "allow": [["g1*", "g2*"]],
          "allowed": [("g0", "g1"), ("g2", "g3", "Never"), ("g3", "g4")]}
m3, _ = scaling_scene(5, "sparse", "translating")
monitor.Scene.from_model(m3, pairs="all", **policy)
for n in [int(x) for x in sys.argv[1:]]:
    model, _ = scaling_scene(n, "sparse", "translating")
    t = time.perf_counter()
    monitor.Scene.from_model(model, pairs="all")
    plain = time.perf_counter() - t
    t = time.perf_counter()
    scene = monitor.Scene.from_model(model, pairs="all", **policy)
    with_policy = time.perf_counter() - t
    tree = monitor.__file__.split("/monitor/")[0]
    print(f"{tree} n={n}: plain {plain * 1e3:.0f} ms, policy {with_policy * 1e3:.0f} ms "
          f"(monitored {len(scene.pair_ids)}, allowed {len(scene.allowed_pairs)})")
