"""benchab 'new' with garbage-collector pauses (gen, ms) printed next to slow certify calls."""
import sys, time, gc
t_gc = {}
def cb(phase, info):
    if phase == "start": t_gc["t"] = time.perf_counter()
    else:
        dt = (time.perf_counter() - t_gc["t"]) * 1e3
        if dt > 5: print(f"  gc gen {info['generation']} {dt:.1f} ms collected {info['collected']}", flush=True)
gc.callbacks.append(cb)
import monitor.certify.engine as E
_c = E.certify
def c(scene, plan, *a, **k):
    t = time.perf_counter(); r = _c(scene, plan, *a, **k); dt = time.perf_counter() - t
    if dt > 0.02: print(f" certify {len(plan.times)} rows {r.verdict} {dt*1e3:.1f} ms", flush=True)
    return r
E.certify = c
if sys.argv[1] == "old":
    import monitor.warmup as W; W.ensure_warm = lambda: None
from monitor.bench.targets import gym_gate
out = gym_gate("monitor/Arm-v0", steps_gated=10, steps_ungated=10, reps=3, brake=True)
print(out["ratio"])
