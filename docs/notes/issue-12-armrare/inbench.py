"""In the bench's own order: pair_windows (quick) first, then the Arm gym_gate (old bench: ensure_warm / gc.collect off):
are the rare-path kernels already loaded when the Arm row runs, and what do its rare calls cost?"""
import sys, time, tempfile, json, gc
from pathlib import Path
import monitor.warmup as W
if sys.argv[1] == "old":
    W.ensure_warm = lambda: None
    gc.collect = lambda *a: 0
from monitor.bench.suites import BenchConfig
from monitor.bench.targets import pair_windows, gym_gate
import rarelog
cfg = BenchConfig(quick=True, out=Path(tempfile.mkdtemp()), log=lambda s: None)
t = time.perf_counter(); pair_windows(cfg); print("pair_windows", round(time.perf_counter() - t, 1), "s")
from monitor.certify import kernels
print("loaded after pair_windows: pair_window", len(kernels.pair_window.signatures), "toleranced imported", "monitor.certify.toleranced" in sys.modules)
if "monitor.certify.fat_kernels" in sys.modules:
    F = sys.modules["monitor.certify.fat_kernels"]; print(" fat_level", len(F.fat_level.signatures), "traj_balls", len(F.traj_balls.signatures))
log = rarelog.install()
out = gym_gate("monitor/Arm-v0", steps_gated=10, steps_ungated=200, reps=3, brake=True)
print(json.dumps({"mode": sys.argv[1], "ratio": round(out["ratio"], 2), "gated_us": round(out["gated_s"] * 1e6), "rare_calls_ms": log}))
