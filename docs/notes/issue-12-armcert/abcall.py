"""In-process A/B of the certify calls of gated steps: this tree's engine with a switch off / on.

PYTHONPATH=<tree>:<tree>/docs/notes/issue-12-tail-design python abcall.py WORK BLOCKS ROUNDS SWITCH...

Records every certify call of BLOCKS blocks of the gated workload (wl.py), then re-runs each
call on a fresh copy of its Plan (so the motion pack is built, as in the gate) ROUNDS times,
alternating "off" (the base's behaviour) and "on" call by call; thread time; prints per group
(waypoints, verdict) the median us off / on and the median of the per-call ratios.
SWITCH: "route" (engine._no_extrusion_route forced False: the base's route), "chunk"
(engine._rest_chunk forced to the base's chunk of _FAST_CHUNK survivors); both: the base tree's path.
"""
import collections, json, sys, time

import numpy as np

import monitor.certify.engine as E
import wl
from monitor.motion.plan import Plan
from monitor.warmup import ensure_warm

work, blocks, rounds = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
switches = sys.argv[4:]
ensure_warm()
saved = []
_cert = E.certify


def certify(scene, plan, **k):
    c = _cert(scene, plan, **k)
    saved.append((plan, k, (len(plan.times), str(c.verdict))))
    return c


E.certify = E._OWN_CERTIFY = certify
W = wl.make(work)
for rep in range(blocks):
    for _ in W.steps(wl.BLOCK[work], rep):
        pass
E.certify = E._OWN_CERTIFY = _cert
scene = W.gate.scene
NAMES = {"route": "_no_extrusion_route", "chunk": "_rest_chunk"}
orig = {s: getattr(E, NAMES[s]) for s in NAMES}
base = {"route": lambda mp, mov: False, "chunk": lambda bud, S, done_to, chunk: chunk}


def mode(on):
    for s in switches:
        setattr(E, NAMES[s], orig[s] if on else base[s])


def fresh(plan):
    return Plan._trusted(np.array(plan.times), np.array(plan._qpos), model=plan._model,
                         mocap_pos=np.array(plan._mocap_pos), mocap_quat=np.array(plan._mocap_quat))


pc = time.thread_time_ns
T = collections.defaultdict(lambda: ([], []))
for r in range(rounds):
    for i, (plan, k, key) in enumerate(saved):
        order = (False, True) if (i + r) % 2 == 0 else (True, False)
        for on in order:
            mode(on)
            p = fresh(plan)
            t = pc()
            _cert(scene, p, **k)
            T[key][on].append(pc() - t)
mode(True)
out = {"work": work, "calls": len(saved), "rounds": rounds, "switches": switches, "groups": {}}
tot_off = tot_on = 0
for key, (off, on) in sorted(T.items()):
    off, on = np.array(off) / 1e3, np.array(on) / 1e3
    tot_off += off.sum(); tot_on += on.sum()
    out["groups"][f"K{key[0]}/{key[1]}"] = {"n": len(off), "off_med": round(float(np.median(off)), 1),
                                           "on_med": round(float(np.median(on)), 1),
                                           "ratio_med": round(float(np.median(on / off)), 3)}
out["total_ratio"] = round(tot_on / tot_off, 3)
out["us_per_step_off_on"] = [round(tot_off / rounds / (blocks * wl.BLOCK[work]), 1),
                             round(tot_on / rounds / (blocks * wl.BLOCK[work]), 1)]
print("AB " + json.dumps(out))
