"""Run hand30 gated (wl.make), keep every joint call's rows; pickle them."""
import pickle, sys
sys.path.insert(0, str(__import__("pathlib").Path(__file__).resolve().parents[1] / "issue-12-tail-design"))
import wl
import monitor.gate as G
out = sys.argv[1]; blocks = int(sys.argv[2])
kept = []
_joint = G.Gate._certify_joint
def cj(self, plan, wr, tr, mp, mq):
    if wr is not None:
        kept.append((wr.copy(), tr.copy(), mp.copy(), mq.copy()))
    return _joint(self, plan, wr, tr, mp, mq)
G.Gate._certify_joint = cj
W = wl.make("hand30")
for rep in range(blocks):
    for _ in W.steps(wl.BLOCK["hand30"], rep):
        pass
print(len(kept), W.gate.stats)
pickle.dump(kept, open(out, "wb"))
