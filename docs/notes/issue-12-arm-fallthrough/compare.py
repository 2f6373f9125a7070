"""Before/after on the recorded windows of a seeded gated Arm episode (same process, same plans).

"before" = engine._full_search switched off (the pairs the whole-shape stage leaves open go straight
to the Python fat-feature checker) and engine._translates replaced by plan.translation_segments, as on
the base commit; "after" = this branch.
Usage: PYTHONPATH=$PWD python docs/notes/issue-12-arm-fallthrough/compare.py [steps] [reps] [seed]
"""
import statistics
import sys
import time

sys.path.insert(0, __file__.rsplit("/", 1)[0])
from record import record  # noqa: E402

from monitor.certify import engine  # noqa: E402

n = int(sys.argv[1]) if len(sys.argv) > 1 else 150
reps = int(sys.argv[2]) if len(sys.argv) > 2 else 5
seed = int(sys.argv[3]) if len(sys.argv) > 3 else 0
g, calls = record(n, seed=seed)
calls = calls[1:]                      # the first call compiles
full = engine._full_search
trans = engine._translates


def run(on, scene, plan, a, k):
    engine._full_search = full if on else (lambda *x, **y: 0)
    engine._translates = trans if on else (lambda plan, mp, b: plan.translation_segments(b) is not None)
    ts = []
    for _ in range(reps):
        t = time.perf_counter()
        c = engine.certify(scene, plan, *a, **k)
        ts.append((time.perf_counter() - t) * 1e3)
    engine._full_search = full
    engine._translates = trans
    return c, statistics.median(ts)


rows, same, diff = [], 0, []
for dt, scene, plan, a, k, _c in calls:
    cb, tb = run(False, scene, plan, a, k)
    ca, ta = run(True, scene, plan, a, k)
    fell = cb.stats["checker_mix"].get("toleranced", 0)
    if cb.verdict == ca.verdict:
        same += 1
    else:
        diff.append((cb.verdict, ca.verdict))
    if fell:
        rows.append((tb, ta, cb.verdict, ca.verdict, cb.earliest_time, ca.earliest_time,
                     cb.witness.time if cb.witness else None, ca.witness.time if ca.witness else None,
                     cb.stats["tests"], ca.stats["tests"], dict(ca.stats["checker_mix"])))
print(f"{len(calls)} windows: verdict identical on {same}, different on {len(diff)} {diff}")
print(f"windows with a fat-feature fall-through (before): {len(rows)}")
for r in rows:
    print("  before %.1f ms after %.1f ms  %s/%s  earliest %.4f/%.4f witness %s/%s tests %d/%d %s" % (
        r[0], r[1], r[2], r[3], r[4] or -1, r[5] or -1, r[6] and round(r[6], 4), r[7] and round(r[7], 4),
        r[8], r[9], r[10]))
if rows:
    print("median ms per fall-through window: before %.2f after %.2f" % (
        statistics.median(r[0] for r in rows), statistics.median(r[1] for r in rows)))
allb = [run(False, *c[1:5])[1] for c in calls]
alla = [run(True, *c[1:5])[1] for c in calls]
print("mean ms per window, all %d: before %.2f after %.2f" % (len(calls), statistics.mean(allb),
                                                             statistics.mean(alla)))
