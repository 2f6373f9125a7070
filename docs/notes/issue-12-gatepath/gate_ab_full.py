"""(Copy of docs/notes/session-2026-11-28-late/gate_ab.py with the bench's full, not quick, tunnel / hand30 blocks and 100-step gym blocks.)

Gated / ungated ratios of the bench's four gate targets, with more repetitions than ``bench --quick``.

PYTHONPATH=<tree> python gate_ab.py [REPS]   (one JSON line: tree, ratios, gated and ungated µs per step)
Run it alternately on two trees (processes interleaved) and compare the ratios pairwise: the bench's
own functions (``monitor.bench.targets``), so the same workloads, controllers and seeds as its rows.
"""
import json
import os
import sys
from pathlib import Path

import monitor
from monitor.bench.suites import BenchConfig
from monitor.bench.targets import gym_gate, hand30_gate, tunnel_gate

reps = int(sys.argv[1]) if len(sys.argv) > 1 else 7
cfg = BenchConfig(quick=False, out=Path("/tmp"), reps=reps)
out = {"tree": os.path.dirname(os.path.dirname(monitor.__file__))}
for key, fn in (("pusher", lambda: gym_gate("Pusher-v5", pairs="mujoco", steps_gated=100, steps_ungated=1000, reps=reps)),
                ("arm", lambda: gym_gate("monitor/Arm-v0", steps_gated=100, steps_ungated=1000, reps=reps)),
                ("tunnel", lambda: tunnel_gate(cfg)), ("hand30", lambda: hand30_gate(cfg))):
    r = fn()
    out[key] = {"ratio": round(r["ratio"], 2), "gated_us": round(1e6 * r["gated_s"], 1),
                "ungated_us": round(1e6 * r["ungated_s"], 2)}
print(json.dumps(out))
