"""Per-window logging cost: MonitorLog.write_window of a gate certificate, and a gated Arm step with a log.

Run one tree per process, interleaved:
  for r in 1 2 3; do for t in /tmp/h12aa_main /work/wt/h12aa; do \
    PYTHONPATH=$t python docs/notes/review-provenance/bench_log.py; done; done
Prints the tree, the median µs of write_window (2000 calls) and of a gated step (300 steps).
"""
import statistics
import tempfile
import time
from pathlib import Path

import mujoco
import numpy as np

import monitor
from monitor.gate import Gate
from monitor.log import MonitorLog

ARM = Path(monitor.__file__).resolve().parents[1] / "models" / "arm" / "scene.xml"
model = mujoco.MjModel.from_xml_path(str(ARM))
tmp = Path(tempfile.mkdtemp())
rng = np.random.default_rng(0)
data = mujoco.MjData(model)
step_us = []
with Gate(model, log=tmp / "g.mcap", log_options={"foxglove": False}) as gate:
    for k in range(330):
        ctrl = rng.uniform(-1, 1, model.nu)
        t0 = time.perf_counter()
        r = gate.step(data, ctrl)
        if k >= 30:
            step_us.append((time.perf_counter() - t0) * 1e6)
plan, cert = r.plan, r.certificate
write_us = []
with MonitorLog(tmp / "w.mcap", model=model, foxglove=False, index=False) as log:
    for _ in range(2000):
        t0 = time.perf_counter()
        log.write_window(float(data.time), plan, cert, ctrl, ctrl, False)
        write_us.append((time.perf_counter() - t0) * 1e6)
print(f"{monitor.__file__.split('/monitor/')[0]:20} write_window {statistics.median(write_us):7.1f} us   "
      f"gated step {statistics.median(step_us):8.1f} us")
