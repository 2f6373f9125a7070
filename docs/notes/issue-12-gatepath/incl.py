"""Inclusive hot time of the engine's per-call functions on a gate's own windows, fresh Plans (µs per certify call).

Usage (from the tree root): PYTHONPATH=$PWD python docs/notes/issue-12-gatepath/incl.py tunnel|arm|hand30 STEPS
Records the gate's Plans with parts.py's first part, then certifies fresh copies 5 times with ~18
engine functions and Plan.translation_segments / body_poses wrapped by a perf_counter_ns timer.
"""
import sys, time, statistics, functools, collections
sys.argv = [sys.argv[0], sys.argv[1], sys.argv[2], "1"]
exec(open("docs/notes/issue-12-gatepath/parts.py").read().split("ns = time.perf_counter_ns")[0])
ns = time.perf_counter_ns
acc = collections.Counter(); cnt = collections.Counter()
def wrap(mod, name):
    f = getattr(mod, name)
    @functools.wraps(f)
    def w(*a, **k):
        t = ns()
        try:
            return f(*a, **k)
        finally:
            acc[name] += ns() - t; cnt[name] += 1
    setattr(mod, name, w)
from monitor.certify import ongoing, extrusion
names = sys.argv_names if hasattr(sys, "argv_names") else None
for n in ["_fast_inputs", "_window_kernel", "_extrusion_decided", "_run_extrusion", "_checked_result", "_all_culled",
          "extrusion_stats", "_window_certificate", "_kernel_decided", "_fast_prep", "_check_model", "_python_stages",
          "_full_search", "_remember_call", "_certify_fast", "deepen", "_request_of", "_python_decided"]:
    if hasattr(engine, n): wrap(engine, n)
orig_ts = PL.Plan.translation_segments
def ts(self, b):
    t = ns()
    try: return orig_ts(self, b)
    finally: acc["Plan.translation_segments"] += ns() - t; cnt["Plan.translation_segments"] += 1
PL.Plan.translation_segments = ts
orig_bp = PL.Plan.body_poses
def bp(self, t_):
    t = ns()
    try: return orig_bp(self, t_)
    finally: acc["Plan.body_poses"] += ns() - t; cnt["Plan.body_poses"] += 1
PL.Plan.body_poses = bp
tot = 0; N = 0
for r in range(5):
    plans = fresh()
    t = ns()
    for p in plans:
        engine.certify(scene, p, request=req)
    tot += ns() - t; N += len(plans)
print(f"certify total {tot / N / 1e3:.1f} µs per call (wrapped)")
for k, v in acc.most_common():
    print(f"{k:28s} {v / N / 1e3:8.2f} µs/call incl   ({cnt[k] / N:.2f} calls/call)")
