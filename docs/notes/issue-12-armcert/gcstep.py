"""gc collections and their time over plain gated steps (no isolation runs): PYTHONPATH=<tree>:<tree>/docs/notes/issue-12-tail-design python gcstep.py WORK BLOCKS."""
import gc, sys, time, collections
import numpy as np
import wl
from monitor.warmup import ensure_warm
ensure_warm()
work = sys.argv[1]; blocks = int(sys.argv[2])
W = wl.make(work)
n = wl.BLOCK[work]
for _ in W.steps(n, 1000): pass
gc.collect()
T = collections.Counter(); C = collections.Counter(); t0 = [0.0]
def cb(phase, info):
    if phase == "start": t0[0] = time.perf_counter()
    else:
        T[info["generation"]] += time.perf_counter() - t0[0]; C[info["generation"]] += 1
gc.callbacks.append(cb)
steps = 0
t = time.thread_time()
for rep in range(blocks):
    for _ in W.steps(n, rep): steps += 1
el = time.thread_time() - t
print(work, "steps", steps, "us/step", el / steps * 1e6, "gc counts", dict(C), "gc us/step", {k: v / steps * 1e6 for k, v in T.items()}, gc.get_threshold(), gc.get_count())
