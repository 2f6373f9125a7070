"""A/B of the bench's gym_gate (Arm, brake) on this tree: argv[1] = 'old' (ensure_warm and gc.collect no-ops: the base bench) or 'new'; argv[2:4] steps reps."""
import sys, time, json, gc
gc_ms = []
_tg = {}
def _gccb(phase, info):
    if phase == "start": _tg["t"] = time.perf_counter()
    else: gc_ms.append((info["generation"], round((time.perf_counter() - _tg["t"]) * 1e3, 1)))
gc.callbacks.append(_gccb)
import monitor.warmup as W
import monitor.certify.engine as E
if sys.argv[1] == "old":   # the base bench: no ensure_warm, no gc.collect() after the warm-up blocks
    W.ensure_warm = lambda: None
    gc.collect = lambda *a: 0
steps, reps = int(sys.argv[2]), int(sys.argv[3])
log, n = [], [0]
_c = E.certify
def c(scene, plan, *a, **k):
    n0 = n[0]; g0 = len(gc_ms); t = time.perf_counter(); r = _c(scene, plan, *a, **k); dt = time.perf_counter() - t
    if n[0] > n0: log.append((round(dt * 1e3, 2), [g for g in gc_ms[g0:] if g[1] > 1]))
    return r
E.certify = c
_ps = E._python_stages
def ps(*a, **k):
    n[0] += 1; return _ps(*a, **k)
E._python_stages = ps
from monitor.bench.targets import gym_gate
t = time.perf_counter()
out = gym_gate("monitor/Arm-v0", steps_gated=steps, steps_ungated=steps, reps=reps, brake=True)
print(json.dumps({"mode": sys.argv[1], "ratio": round(out["ratio"], 2), "gated_us": round(out["gated_s"] * 1e6), "ungated_us": round(out["ungated_s"] * 1e6),
                  "rare_calls_ms": log, "verdicts": out["verdicts"], "wall_s": round(time.perf_counter() - t, 2)}))
