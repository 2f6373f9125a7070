import pickle, sys, time, collections
import numpy as np
sys.path.insert(0, str(__import__("pathlib").Path(__file__).resolve().parents[1] / "issue-12-tail-design"))
import wl
import monitor.certify.engine as E
from monitor.motion.plan import Plan
pc = time.thread_time   # CPU time of this thread: robust to the shared machine's time-sharing
kept = pickle.load(open(sys.argv[1], "rb"))
W = wl.make("hand30")
for _ in W.steps(2, 0): pass
g = W.gate; req = g._plain_request(); scene = g.scene
T = collections.defaultdict(list)
_wk = E._window_kernel
idx = [0]
def wk(*a):
    t = pc(); r = _wk(*a); T[min(idx[0], 3)].append(pc() - t); idx[0] += 1; return r
E._window_kernel = wk
tot = []
for r in range(3):
    for (wr, tr, mp, mq) in kept:
        p = Plan._trusted(np.concatenate((wr[:, 0], tr[1:, 0])), np.concatenate((wr[:, 1:], tr[1:, 1:])),
                          model=W.model, mocap_pos=mp.copy(), mocap_quat=mq.copy())
        idx[0] = 0
        t = pc(); E.certify(scene, p, request=req); tot.append(pc() - t)
print("certify median", 1e6 * np.median(tot))
for k in sorted(T): print("call", k, "n", len(T[k]), "median us %.1f" % (1e6 * np.median(T[k])), "sum/cert %.1f" % (1e6 * sum(T[k]) / len(tot)))
