"""Q3 / Q4 cost: gated / ungated per step for several brake horizons (and brake=False), interleaved.

PYTHONPATH=<tree> python docs/notes/issue-12-tail-design/ratios.py WORK REPS H1 [H2 ...]

One process: the ungated env and one gated env per variant (each horizon H in s, and "off" =
brake=False), blocks as the bench's (wl.BLOCK steps, block rep r seeded r), every variant's
block r run right after the others' block r (interleaved). Clock: thread time. One untimed
warm-up block each, then gc.collect(). Prints "RATIOS {...}": per variant the median s per
step, the median of the per-rep ratios gated / ungated (same rep), and the tail substeps per step.
"""
import gc, json, sys

import numpy as np

import wl

work, reps = sys.argv[1], int(sys.argv[2])
variants = sys.argv[3:]
n = wl.BLOCK[work]
base = wl.make(work)
W = {v: (wl.make(work, brake=False) if v == "off" else wl.make(work, horizon=float(v))) for v in variants}
base.ungated(5, 1000)
for w in W.values():
    for _ in w.steps(2, 1000):
        pass
gc.collect()
U, G_ = [], {v: [] for v in W}
sub = {v: [0, 0] for v in W}
for r in range(reps):
    U.append(base.ungated(max(n, 100), r % 10))
    for v, w in W.items():
        s0 = w.gate._rollout.tail_substeps
        G_[v].append(w.gated(n, r % 10))
        sub[v][0] += w.gate._rollout.tail_substeps - s0
        sub[v][1] += n
out = {"work": work, "reps": reps, "ungated_us": 1e6 * float(np.median(U)), "variants": {}}
for v in W:
    out["variants"][v] = {"gated_us": 1e6 * float(np.median(G_[v])),
                          "ratio": float(np.median(np.array(G_[v]) / np.array(U))),
                          "tail_substeps_per_step": sub[v][0] / sub[v][1],
                          "brake_steps": W[v].gate.brake_steps if v != "off" else 0}
print("RATIOS " + json.dumps(out))
