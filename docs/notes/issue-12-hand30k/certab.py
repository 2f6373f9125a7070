"""Isolated certify of captured hand30 joint (window + tail) plans: median over plans of the median of ROUNDS.

PYTHONPATH=<tree> python certab.py joint.pkl ROUNDS  -> "CERT {json}" (thread time, gate's plain request)
"""
import json, pickle, sys, time
import numpy as np
sys.path.insert(0, str(__import__("pathlib").Path(__file__).resolve().parents[1] / "issue-12-tail-design"))
import wl
import monitor.certify.engine as E
from monitor.motion.plan import Plan
pc = time.thread_time
kept = pickle.load(open(sys.argv[1], "rb"))[:20]   # one block: 20 distinct steps
rounds = int(sys.argv[2])
W = wl.make("hand30")
for _ in W.steps(2, 0):
    pass
g = W.gate; req = g._plain_request(); scene = g.scene
def plans():
    for wr, tr, mp, mq in kept:
        yield Plan._trusted(np.concatenate((wr[:, 0], tr[1:, 0])), np.concatenate((wr[:, 1:], tr[1:, 1:])),
                            model=W.model, mocap_pos=mp.copy(), mocap_quat=mq.copy())
per = [[] for _ in kept]
for r in range(rounds):
    for i, p in enumerate(plans()):      # a fresh Plan object each time: nothing cached per plan
        t = pc(); E.certify(scene, p, request=req); per[i].append(pc() - t)
print("CERT " + json.dumps({"tree": E.__file__, "plans": len(kept), "rounds": rounds,
                            "median_us": 1e6 * float(np.median([np.median(x) for x in per]))}))
