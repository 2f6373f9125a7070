"""Cold cache: CPU of the first certify, then of the first pair-search entry in the same process.

The certify is trace.py's (arm scene); the entry is monitor.warmup's call of
kernels.check_pair_window, which compiles pair_window on top of the cached callees.

usage: NUMBA_CACHE_DIR=<empty dir> PYTHONPATH=<tree> python pairentry.py   -> "PAIRENTRY {json}"
"""
import json
import time

import mujoco
import numpy as np

import monitor
from monitor import warmup
from monitor._paths import scene_path

c0 = time.process_time()
model = mujoco.MjModel.from_xml_path(str(scene_path("arm")))
scene = monitor.Scene.from_model(model)
q0 = model.qpos0.copy()
q1 = q0.copy()
q1[0] += 0.05
q1[2] += 0.05
plan = monitor.Plan(np.array([0.0, 0.01]), np.stack([q0, q1]), model=model)
cert = monitor.certify(scene, plan)
c1 = time.process_time()
v = warmup._pair_search(scene, plan)
c2 = time.process_time()
print("PAIRENTRY " + json.dumps({"tree": monitor.__file__, "certify_cpu_s": c1 - c0,
                                 "pair_entry_cpu_s": c2 - c1, "verdicts": [str(cert.verdict), v]}))
