"""The bench's gym_gate (Arm, brake) with the rare Python-stage calls logged; argv[1]=preload: load the rare path first."""
import sys, time, json
import monitor.certify.engine as E
pre = sys.argv[1] == "preload"
steps, reps = int(sys.argv[2]), int(sys.argv[3])
log = []
_c = E.certify
def c(scene, plan, *a, **k):
    n0 = n[0]; t = time.perf_counter(); r = _c(scene, plan, *a, **k); dt = time.perf_counter() - t
    if n[0] > n0: log.append(round(dt * 1e3, 2))
    return r
E.certify = c
n = [0]
_ps = E._python_stages
def ps(*a, **k):
    n[0] += 1; return _ps(*a, **k)
E._python_stages = ps
if pre:
    from monitor.warmup import ensure_warm
    t = time.perf_counter(); ensure_warm(); print("ensure_warm", round(time.perf_counter() - t, 3), "s")
from monitor.bench.targets import gym_gate
out = gym_gate("monitor/Arm-v0", steps_gated=steps, steps_ungated=steps, reps=reps, brake=True)
print(json.dumps({"mode": sys.argv[1], "ratio": out["ratio"], "gated_us": out["gated_s"] * 1e6, "ungated_us": out["ungated_s"] * 1e6,
                  "rare_calls_ms": log, "verdicts": out["verdicts"]}))
