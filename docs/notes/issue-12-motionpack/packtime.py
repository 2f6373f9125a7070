"""Per-call time of pack_trajectory and _pack_agrees on the Plans real gates build.

usage: PYTHONPATH=<tree> python packtime.py tunnel|Pusher-v5|monitor/Arm-v0 STEPS [PASSES]
Records the rows of every Plan the gate builds over STEPS gated steps (seeded), then, per pass,
rebuilds each Plan from its rows (fresh object) and times pack_trajectory(plan) and
_pack_agrees(plan, pack) with perf_counter. Prints medians in us (one line).
"""
import sys
import time
import warnings

import numpy as np

warnings.simplefilter("ignore")
import monitor.certify.kernels as KS  # noqa: E402
from monitor.motion.pack import pack_trajectory  # noqa: E402
from monitor.motion.plan import Plan  # noqa: E402
from monitor.warmup import ensure_warm  # noqa: E402

sys.path.insert(0, __file__.rsplit("/", 2)[0] + "/issue-12-gate-5")  # its runners.py
from runners import runner  # noqa: E402

work, n = sys.argv[1], int(sys.argv[2])
passes = int(sys.argv[3]) if len(sys.argv) > 3 else 5
ensure_warm()
rec = []
orig = Plan.__dict__["_trusted"].__func__


def spy(cls, times, qpos, model, **k):
    """Record the rows of every Plan the gate builds."""
    rec.append((np.array(times), np.array(qpos), model, {a: (b.copy() if isinstance(b, np.ndarray) else b)
                                                          for a, b in k.items()}))
    return orig(cls, times, qpos, model, **k)


Plan._trusted = classmethod(spy)
runner(work)(n)
Plan._trusted = classmethod(orig)
plans_rows = [r for r in rec if r[0].shape[0] >= 2]
tp, ta = [], []
for _ in range(passes):
    for t, q, m, k in plans_rows:
        p = Plan._trusted(t.copy(), q.copy(), m, **k)
        a = time.perf_counter()
        mp = pack_trajectory(p)
        b = time.perf_counter()
        ok = KS._pack_agrees(p, mp)
        c = time.perf_counter()
        assert ok
        tp.append(b - a)
        ta.append(c - b)
Ks = [r[0].shape[0] for r in plans_rows]
print(f"{work}: {len(plans_rows)} plans (K={min(Ks)}..{max(Ks)}), {passes} passes: pack_trajectory "
      f"{1e6 * np.median(tp):.1f} us, _pack_agrees {1e6 * np.median(ta):.1f} us, "
      f"sum {1e6 * np.median(np.add(tp, ta)):.1f} us")
