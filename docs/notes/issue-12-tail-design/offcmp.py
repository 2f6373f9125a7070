"""Why brake=False is not "the gate minus its tail" on the Arm: verdicts and certify time by verdict.

PYTHONPATH=<tree> python docs/notes/issue-12-tail-design/offcmp.py [WORK] [BLOCKS]

The same seeded blocks (wl.py) gated with brake=False and with the default brake; per run the
gate's counters and, per certify verdict, the calls and the thread time per gated step (µs).
"""
import collections, json, sys, time

import monitor.certify.engine as E
import wl

work = sys.argv[1] if len(sys.argv) > 1 else "monitor/Arm-v0"
blocks = int(sys.argv[2]) if len(sys.argv) > 2 else 30
calls, T = collections.Counter(), collections.Counter()
_c = E.certify
def certify(scene, plan, **k):
    t = time.thread_time()
    r = _c(scene, plan, **k)
    T[str(r.verdict)] += time.thread_time() - t
    calls[str(r.verdict)] += 1
    return r
E.certify = certify
n = wl.BLOCK[work]
for brake in (False, True):
    W = wl.make(work, brake=brake)
    for _ in W.steps(2, 1000):
        pass
    calls.clear(); T.clear(); s0 = dict(W.gate.stats)
    for rep in range(blocks):
        for _ in W.steps(n, rep):
            pass
    s = {k: W.gate.stats[k] - s0[k] for k in ("windows", "replaced", "violation", "uncertain", "fallback_uncertified")}
    print("OFFCMP " + json.dumps({"work": work, "brake": brake, "stats": s, "certify_calls": dict(calls),
                                  "certify_us_per_step": {k: 1e6 * v / s["windows"] for k, v in T.items()}}))
