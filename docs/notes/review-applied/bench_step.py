"""Gated monitor/Arm step with a log (foxglove off): median µs of accepted and of replaced steps.

Run one tree per process, interleaved (cwd = the tree, see review-provenance.md's caveat):
  for r in 1 2 3; do for t in /tmp/h12ac_main /work/wt/h12ac; do \
    (cd $t && PYTHONPATH=$t python /work/wt/h12ac/docs/notes/review-applied/bench_step.py); \
  done; done
"""
import statistics
import tempfile
import time
from pathlib import Path

import mujoco
import numpy as np

import monitor
from monitor.gate import Gate

ARM = Path(monitor.__file__).resolve().parents[1] / "models" / "arm" / "scene.xml"
model = mujoco.MjModel.from_xml_path(str(ARM))
tmp = Path(tempfile.mkdtemp())
rng = np.random.default_rng(0)
data = mujoco.MjData(model)
acc, rep = [], []
with Gate(model, log=tmp / "g.mcap", log_options={"foxglove": False}) as gate:
    for k in range(430):
        ctrl = rng.uniform(model.actuator_ctrlrange[:, 0], model.actuator_ctrlrange[:, 1])
        t0 = time.perf_counter()
        r = gate.step(data, ctrl)
        us = (time.perf_counter() - t0) * 1e6
        if k >= 30:
            (rep if r.replaced else acc).append(us)
        if k % 100 == 99:
            mujoco.mj_resetData(model, data)
            gate.reset()
    windows = gate._log.windows
med_rep = statistics.median(rep) if rep else float("nan")
tree = monitor.__file__.split('/monitor/')[0]
print(f"{tree:20} accepted {statistics.median(acc):8.1f} us (n={len(acc)})  "
      f"replaced {med_rep:8.1f} us (n={len(rep)})  log windows {windows}")
