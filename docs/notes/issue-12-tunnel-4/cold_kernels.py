"""Cold compile cost of this branch's two new kernels, on an otherwise warm numba cache.

NUMBA_CACHE_DIR=<a copy of a warmed cache without the witness_kernels and swept_plan_pair_kernel entries>
PYTHONPATH=<this tree> python docs/notes/issue-12-tunnel-4/cold_kernels.py
(thread CPU and wall seconds of each warm(); on a fully warm cache they only load.)
"""
import time
import monitor.certify.engine, monitor.geometry.distance
from monitor.certify import extrusion_swept as X, witness_kernels as W
import numpy as np
for name, f in (("confirm_kernel", W.warm), ("swept kernels (plan variant new)", X.warm)):
    t = time.thread_time(); w = time.perf_counter(); f()
    print(f"{name}: {time.thread_time() - t:.2f} s CPU, {time.perf_counter() - w:.2f} s wall")
