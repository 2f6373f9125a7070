"""Whole SafetyGate(monitor/Arm-v0) runs, 30 seeded steps, signed vs unsigned log, interleaved in one process."""
import os, sys, time, statistics
sys.path.insert(0, "tests")
os.makedirs("/tmp/signlog", exist_ok=True)
from test_review_applied import _arm_run
from monitor.log import MonitorLog
key = bytes(range(32))
_arm_run("/tmp/signlog/warm.mcap", steps=5)
t = {"unsigned": [], "signed": []}
for rep in range(8):
    order = (("unsigned", False), ("signed", key)) if rep % 2 == 0 else (("signed", key), ("unsigned", False))
    for name, k in order:
        log = MonitorLog(f"/tmp/signlog/armt-{name}.mcap", key=k, foxglove=True, index=False)
        a = time.perf_counter(); _arm_run(log, steps=30); log.close(); t[name].append(time.perf_counter() - a)
u, s = statistics.median(t["unsigned"]), statistics.median(t["signed"])
print(f"median run: unsigned {u*1e3:.1f} ms, signed {s*1e3:.1f} ms, ratio {s/u:.3f}, per window {(s-u)/31*1e6:.0f} us")
print("unsigned", [round(x*1e3, 1) for x in t["unsigned"]]); print("signed", [round(x*1e3, 1) for x in t["signed"]])
