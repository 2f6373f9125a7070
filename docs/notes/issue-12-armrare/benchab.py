"""A/B of the bench's gym_gate (Arm, brake) on this tree: argv[1] = 'old' (ensure_warm and gc.collect no-ops: the base bench) or 'new'; argv[2:4] steps reps."""
import sys, time, json, gc
import monitor.warmup as W
import rarelog
if sys.argv[1] == "old":   # the base bench: no ensure_warm, no gc.collect() after the warm-up blocks
    W.ensure_warm = lambda: None
    gc.collect = lambda *a: 0
steps, reps = int(sys.argv[2]), int(sys.argv[3])
log = rarelog.install(with_gc=True)
from monitor.bench.targets import gym_gate
t = time.perf_counter()
out = gym_gate("monitor/Arm-v0", steps_gated=steps, steps_ungated=steps, reps=reps, brake=True)
print(json.dumps({"mode": sys.argv[1], "ratio": round(out["ratio"], 2), "gated_us": round(out["gated_s"] * 1e6), "ungated_us": round(out["ungated_s"] * 1e6),
                  "rare_calls_ms": log, "verdicts": out["verdicts"], "wall_s": round(time.perf_counter() - t, 2)}))
