"""Record slow Arm windows (record.py) and show, per fall-through pair, what the kernel and Python did.

Usage: PYTHONPATH=$PWD python docs/notes/issue-12-arm-fallthrough/probe.py [steps]
"""
import cProfile
import pstats
import sys
import time

sys.path.insert(0, __file__.rsplit("/", 1)[0])
from record import record  # noqa: E402

from monitor.certify import engine, toleranced  # noqa: E402

n = int(sys.argv[1]) if len(sys.argv) > 1 else 150
g, calls = record(n)
slow = [c for c in calls[1:] if c[0] > 20]
print(f"{len(calls)} calls, {len(slow)} > 20 ms")

orig_cp = toleranced.check_pairs
orig_fw = engine._find_witness
log = []


def cp(traj, items, window, margin, epsilon, *a, **k):
    t = time.perf_counter()
    outs = orig_cp(traj, items, window, margin, epsilon, *a, **k)
    dt = (time.perf_counter() - t) * 1e3
    for (sa, ba, sb, bb), o in zip(items, outs):
        log.append(("check_pairs", dt, sa.kind, len(sa.points) if sa.points is not None else 0, sb.kind,
                    len(sb.points) if sb.points is not None else 0, ba, bb, o.verdict, o.tests, o.max_depth,
                    o.intervals[:4], len(o.intervals), o.info.get("items"), window, margin, epsilon))
    return outs


def fw(plan, ga, gb, times, margin, tol, *a):
    t = time.perf_counter()
    w = orig_fw(plan, ga, gb, times, margin, tol, *a)
    log.append(("find_witness", (time.perf_counter() - t) * 1e3, len(times), None if w is None else w.time))
    return w


toleranced.check_pairs = cp
engine._find_witness = fw
for dt, scene, plan, a, k, c in slow:
    log.clear()
    t = time.perf_counter()
    c2 = engine.certify(scene, plan, *a, **k)
    dt2 = (time.perf_counter() - t) * 1e3
    print(f"--- recorded {dt:.1f} ms, replay {dt2:.1f} ms, {c2.verdict} mix={c2.stats['checker_mix']}")
    for e in log:
        print("   ", e)
    for p in c2.pairs:
        if p.method == "toleranced" and p.verdict != "certified" or p.method == "toleranced":
            print("    pair", p.geoms, p.verdict, p.method, p.tests, p.intervals[:3],
                  None if p.witness is None else p.witness.time)
toleranced.check_pairs = orig_cp
engine._find_witness = orig_fw
dt, scene, plan, a, k, c = max(slow, key=lambda c: c[0])
pr = cProfile.Profile()
pr.enable()
for _ in range(3):
    engine.certify(scene, plan, *a, **k)
pr.disable()
pstats.Stats(pr).sort_stats("tottime").print_stats(25)
