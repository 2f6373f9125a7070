"""Q1 / Q3(a, d): what the braking tails of one workload are and how they are used.

PYTHONPATH=<tree> python docs/notes/issue-12-tail-design/tailstats.py WORK BLOCKS [HORIZON] [SAMPLES]

WORK as in wl.py; BLOCKS blocks of the bench's length (wl.BLOCK); HORIZON brake_horizon in s
(default 0.25). Prints one JSON line "STATS {...}":
* tails: count, substeps per tail (min / median / max), how many ended before max_steps,
  max |qvel| at the tail's end (median, p10, p90, min), at its start (the window's end);
* steps: accepted, replaced; of the replaced: committed tail reused (_tail_covers), fresh
  fallback windows after the tail was exhausted / with no committed brake and their verdicts;
  brake_rejected, fallback_uncertified, runs of consecutive replaced steps;
* time (thread time, us per gated step, timers on): tail physics (Rollout.brake_rows), window
  physics (Rollout._window: proposal, replay, fallback windows), certify calls by waypoints;
* certify split on SAMPLES joint-call steps re-certified in isolation after the run (median of
  3 interleaved rounds, the joint call's request): window alone, tail alone, window + tail.
"""
import collections, json, sys

import numpy as np

import monitor.certify.engine as E
import monitor.gate as G
import wl

work, blocks = sys.argv[1], int(sys.argv[2])
horizon = float(sys.argv[3]) if len(sys.argv) > 3 else 0.25
samples = int(sys.argv[4]) if len(sys.argv) > 4 else 40
pc = wl.pc
T = collections.Counter()
tails = []          # (substeps, max|qvel| start, max|qvel| end)
calls = collections.Counter()
on = {"t": False}

_brake_rows = G.Rollout.brake_rows
def brake_rows(self, *a, **k):
    t = pc()
    rows, brake = _brake_rows(self, *a, **k)
    T["tail_physics"] += pc() - t
    nq = self.model.nq
    q = np.abs(rows[:, 1 + nq:])
    tails.append((len(rows) - 1, float(q[0].max()), float(q[-1].max()), a[3]))
    return rows, brake
G.Rollout.brake_rows = brake_rows

_window = G.Rollout._window
def window(self, *a, **k):
    t = pc()
    try:
        return _window(self, *a, **k)
    finally:
        T["window_physics"] += pc() - t
G.Rollout._window = window

_cert = E.certify
def certify(scene, plan, **k):
    t = pc()
    c = _cert(scene, plan, **k)
    dt = pc() - t
    T["certify"] += dt
    calls[len(plan.times)] += 1
    T[f"certify_K{len(plan.times)}"] += dt
    return c
E.certify = certify

pairs_kept = []
_joint = G.Gate._certify_joint
def certify_joint(self, plan, window_rows, tail_rows, mp, mq):
    r = _joint(self, plan, window_rows, tail_rows, mp, mq)
    if r is not None and len(pairs_kept) < 4 * samples:
        pairs_kept.append((window_rows, tail_rows, mp.copy(), mq.copy()))
    return r
G.Gate._certify_joint = certify_joint

W = wl.make(work, horizon)
g = W.gate
n = wl.BLOCK[work]
# warm-up block (kernel loads, ACM), untimed and uncounted
for _ in W.steps(2, 1000):
    pass
tails.clear(); T.clear(); calls.clear(); pairs_kept.clear()
stats0 = dict(g.stats)
rec = []
runs, run = [], 0
steps = 0
kinds = collections.Counter()   # replaced steps by what was applied, and the fallback's verdict
same_as_brake = 0               # proposals equal (bytes) to the committed brake (design (d))
_decide = G.Gate.decide
def decide(self, data, ctrl, **k):
    global same_as_brake
    c = self._committed
    if c is not None and np.asarray(ctrl, dtype=np.float64).tobytes() == np.asarray(c, np.float64).tobytes():
        same_as_brake += 1
    reused0 = self.stats["tail_reused"]
    r = _decide(self, data, ctrl, **k)
    if r.replaced:
        committed = c is not None and np.asarray(r.applied_ctrl, np.float64).tobytes() == np.asarray(c, np.float64).tobytes()
        kind = ("tail_reused" if self.stats["tail_reused"] > reused0 else
                "committed_brake_fresh_window" if committed else "hold_no_committed_brake")
        kinds[(kind, str(r.applied_verdict))] += 1
    return r
G.Gate.decide = decide
for rep in range(blocks):
    run = 0
    for r in W.steps(n, rep):
        steps += 1
        if r.replaced:
            run += 1
        else:
            if run:
                runs.append(run)
            run = 0
    if run:
        runs.append(run)
st = {k: g.stats[k] - stats0[k] for k in g.stats}

# fallback windows that were not a reused tail window, by verdict: counted from stats
subs = np.array([t[0] for t in tails]) if tails else np.zeros(0)
qs = np.array([t[1] for t in tails]) if tails else np.zeros(0)
qe = np.array([t[2] for t in tails]) if tails else np.zeros(0)
maxs = int(g.brake_steps)

def pct(x, p):
    return float(np.percentile(x, p)) if len(x) else None

out = {
    "work": work, "horizon": horizon, "brake_steps": maxs, "steps": steps,
    "tails": len(tails), "tail_substeps": {"min": int(subs.min()) if len(subs) else None,
                                           "median": pct(subs, 50), "max": int(subs.max()) if len(subs) else None,
                                           "ended_early": int((subs < maxs).sum()),
                                           "total": int(subs.sum())},
    "qvel_end_max": {"median": pct(qe, 50), "p10": pct(qe, 10), "p90": pct(qe, 90),
                     "min": float(qe.min()) if len(qe) else None},
    "qvel_start_max": {"median": pct(qs, 50), "p90": pct(qs, 90)},
    "stats": {k: st[k] for k in ("windows", "replaced", "brake_rejected", "tail_reused", "tail_refuted",
                                 "fallback_uncertified", "joint", "certified", "violation", "uncertain",
                                 "tail_replay_differs")},
    "replaced_runs": {"count": len(runs), "median": pct(np.array(runs), 50), "max": max(runs) if runs else 0,
                      "hist": dict(sorted(collections.Counter(runs).items()))},
    "replaced_by_kind": {f"{a}/{b}": v for (a, b), v in sorted(kinds.items())},
    "proposal_equals_committed_brake": same_as_brake,
    "us_per_step": {k: 1e6 * v / steps for k, v in sorted(T.items())},
    "certify_calls_per_step": {k: v / steps for k, v in sorted(calls.items())},
}

# certify split on kept joint steps (isolation, same scene, the joint call's plain request)
if pairs_kept:
    from monitor.motion.plan import Plan
    E.certify = _cert
    req = g._plain_request()
    scene = g.scene
    rng = np.random.default_rng(0)
    idx = rng.choice(len(pairs_kept), size=min(samples, len(pairs_kept)), replace=False)
    res = {"window": [], "tail": [], "joint": []}
    for i in idx:
        wr, tr, mp, mq = pairs_kept[i]
        plans = {
            "window": Plan._trusted(wr[:, 0].copy(), wr[:, 1:].copy(), model=W.model, mocap_pos=mp.copy(),
                                    mocap_quat=mq.copy()),
            "tail": Plan._trusted(tr[:, 0].copy(), tr[:, 1:].copy(), model=W.model, mocap_pos=mp.copy(),
                                  mocap_quat=mq.copy()),
            "joint": Plan._trusted(np.concatenate((wr[:, 0], tr[1:, 0])), np.concatenate((wr[:, 1:], tr[1:, 1:])),
                                   model=W.model, mocap_pos=mp.copy(), mocap_quat=mq.copy()),
        }
        per = {k: [] for k in plans}
        for _ in range(3):
            for k, p in plans.items():
                t = pc(); _cert(scene, p, request=req); per[k].append(pc() - t)
        for k in per:
            res[k].append(float(np.median(per[k])))
    out["certify_isolated_us"] = {k: 1e6 * float(np.median(v)) for k, v in res.items()}
    out["certify_isolated_us"]["samples"] = len(idx)
    out["certify_isolated_us"]["joint_minus_window_median"] = 1e6 * float(
        np.median(np.array(res["joint"]) - np.array(res["window"])))
print("STATS " + json.dumps(out))
