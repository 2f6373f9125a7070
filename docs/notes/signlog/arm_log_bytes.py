"""Bytes of a signed vs an unsigned SafetyGate(monitor/Arm-v0) log (30 seeded steps, finalised)."""
import os, sys
sys.path.insert(0, "tests")
os.makedirs("/tmp/signlog", exist_ok=True)
from test_review_applied import _arm_run
from monitor.log import MonitorLog
key = bytes(range(32))
for name, k in (("unsigned", False), ("signed", key)):
    path = f"/tmp/signlog/arm-{name}.mcap"
    with MonitorLog(path, key=k, foxglove=True) as log:
        _arm_run(log, steps=30)
    print(name, os.path.getsize(path), "bytes", log.windows, "windows")
