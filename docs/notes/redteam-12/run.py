"""Run rt12 fuzz cases: [RT12_SWEEP=1] [RT12_TESTS=1] python run.py OUT.jsonl SEED0 SEED1 [METHODS]

RT12_SWEEP: force the sweep (engine.SWEEP_MIN_GEOMS = 0); RT12_TESTS: a test budget instead of seconds.
Needs PYTHONPATH=<tree to test>; the generator (gen.py) is read from /tmp/rt12 (copy this folder there)."""
import json
import sys
import time
import traceback

import mujoco
import numpy as np

sys.path.insert(0, "/tmp/rt12")
import gen  # noqa: E402

import monitor  # noqa: E402
import os  # noqa: E402
from monitor.certify import engine  # noqa: E402
if os.environ.get("RT12_SWEEP"):
    engine.SWEEP_MIN_GEOMS = 0
BUDGET = {"tests": 100000} if os.environ.get("RT12_TESTS") else {"seconds": 120}

out = open(sys.argv[1], "w")
s0, s1 = int(sys.argv[2]), int(sys.argv[3])
methods = sys.argv[4].split(",") if len(sys.argv) > 4 else ["toleranced"]
print(monitor.__file__, file=sys.stderr)
for seed in range(s0, s1):
    try:
        m, times, qpos, meta = gen.make_case(seed)
    except Exception as e:   # noqa: BLE001
        print("gen fail", seed, e, file=sys.stderr)
        continue
    names = gen.geom_names(m)
    pairs = gen.candidate_pairs(m)
    ids = [(names.index(a), names.index(b)) for a, b in pairs]
    orc = gen.Oracle(m, times, qpos)
    rng = np.random.default_rng(seed + 999)
    t0, t1 = float(times[0]), float(times[-1])
    if rng.random() < 0.3:
        u = np.sort(rng.uniform(t0, t1, 2))
        t0, t1 = float(u[0]), float(u[1])
    win = (t0, t1)
    dmin, dsamp = orc.minimum(ids, t0, t1)
    plan = monitor.Plan(times, qpos, model=m)
    scene = monitor.Scene.from_model(m, pairs=pairs)
    runs = []
    dstart = np.array(orc.at(t0, ids))
    ok = np.flatnonzero(dstart > 0.002)
    if not ok.size:
        continue
    order = ok[np.argsort(dmin[ok])]
    for delta in (1e-3, 1e-5):
        for i in order[:3]:
            for sgn in (+1, -1):
                mg = dmin[i] + sgn * delta
                if mg < 0:
                    if sgn < 0:
                        continue
                    mg = 0.0
                runs.append(([int(i)], float(mg)))
        for sgn in (+1, -1):
            mg = dmin[ok].min() + sgn * delta
            if mg < 0:
                if sgn < 0:
                    continue
                mg = 0.0
            if mg < dstart[ok].min():
                runs.append(([int(x) for x in ok], float(mg)))
    for method in methods:
        for sel, mg in runs:
            rec = dict(seed=seed, meta=meta, method=method, sel=sel, margin=mg, win=win,
                       dmin=[float(dmin[i]) for i in sel])
            try:
                cert = monitor.certify(scene, plan, margin=mg, epsilon=1e-4, method=method, window=win,
                                       pairs=[pairs[i] for i in sel], budget=BUDGET)
                rec["verdict"] = str(cert.verdict)
                rec["clearance"] = float(cert.clearance)
                rec["pairs"] = [(p.geoms, str(p.verdict), p.method, float(p.clearance),
                                 (float(p.witness.time) if p.witness is not None else None)) for p in cert.pairs]
                rec["witness"] = None if cert.witness is None else (float(cert.witness.time), cert.witness.geoms)
            except Exception as e:  # noqa: BLE001
                rec["error"] = repr(e)
                rec["tb"] = traceback.format_exc()[-800:]
            out.write(json.dumps(rec) + "\n")
    out.flush()
