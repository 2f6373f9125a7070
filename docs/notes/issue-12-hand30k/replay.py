"""Replay captured hand30 joint plans through certify; per-stage Python timers."""
import pickle, sys, time, collections
import numpy as np
sys.path.insert(0, str(__import__("pathlib").Path(__file__).resolve().parents[1] / "issue-12-tail-design"))
import wl
import monitor.certify.engine as E
import monitor.certify.kernels as KS
from monitor.motion.plan import Plan
pc = time.thread_time
kept = pickle.load(open(sys.argv[1], "rb"))
reps = int(sys.argv[2]) if len(sys.argv) > 2 else 5
W = wl.make("hand30")
for _ in W.steps(2, 0):
    pass
g = W.gate; req = g._plain_request(); scene = g.scene
def plan_of(wr, tr, mp, mq):
    return Plan._trusted(np.concatenate((wr[:, 0], tr[1:, 0])), np.concatenate((wr[:, 1:], tr[1:, 1:])),
                         model=W.model, mocap_pos=mp.copy(), mocap_quat=mq.copy())
T = collections.defaultdict(float); N = collections.Counter()
def wrap(mod, name, key=None):
    f = getattr(mod, name); key = key or name
    def w(*a, **k):
        t = pc()
        try:
            return f(*a, **k)
        finally:
            T[key] += pc() - t; N[key] += 1
    setattr(mod, name, w)
for nm in ("_fast_inputs", "_fast_prep", "_window_kernel", "_python_stages", "_full_search", "_kernel_decided",
           "_all_culled", "_select", "_sweep_rows", "_plan_inputs"):
    if hasattr(E, nm):
        wrap(E, nm)
wrap(KS, "trajectory_pack_memo")
E_cert = E.certify
tot = []
info_log = []
_wk = E._window_kernel
for r in range(reps):
    for (wr, tr, mp, mq) in kept:
        p = plan_of(wr, tr, mp, mq)
        t = pc(); c = E_cert(scene, p, request=req); tot.append(pc() - t)
        if r == 0:
            info_log.append((c.verdict, c.clearance, c.stats["pairs_culled"], c.stats["tests"], dict(c.stats["checker_mix"])))
n = len(tot)
print("certify median us", 1e6 * np.median(tot), "mean", 1e6 * np.mean(tot), "calls", n)
for k in sorted(T):
    print(f"{k:25s} calls/cert {N[k]/n:5.2f}  us/cert {1e6*T[k]/n:8.1f}")
for x in info_log[:5]:
    print(x)
