"""The bench's gym_gate (Arm, brake) with the rare Python-stage calls logged; argv[1]=preload: ensure_warm first. Written BEFORE commit d764d95 (gym_gate now preloads itself): use benchab.py for the A/B on this tree."""
import sys, time, json
import rarelog
pre = sys.argv[1] == "preload"
steps, reps = int(sys.argv[2]), int(sys.argv[3])
log = rarelog.install()
if pre:
    from monitor.warmup import ensure_warm
    t = time.perf_counter(); ensure_warm(); print("ensure_warm", round(time.perf_counter() - t, 3), "s")
from monitor.bench.targets import gym_gate
out = gym_gate("monitor/Arm-v0", steps_gated=steps, steps_ungated=steps, reps=reps, brake=True)
print(json.dumps({"mode": sys.argv[1], "ratio": out["ratio"], "gated_us": out["gated_s"] * 1e6, "ungated_us": out["ungated_s"] * 1e6,
                  "rare_calls_ms": log, "verdicts": out["verdicts"]}))
