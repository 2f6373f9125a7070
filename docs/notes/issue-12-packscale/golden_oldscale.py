"""The 5 golden calls that moved, re-run on this tree with each pack's tol[3] reset to the FORMER
definition (FK at every waypoint): if they then match the recording, the scale value alone moved them."""
import json
import sys
from pathlib import Path

import numpy as np

tests = Path(sys.argv[1]) / "tests"
sys.path.insert(0, str(tests))
import test_engine_entry as T
from _engine_entry_cases import _summary, calls

import monitor.motion.kernel as KN
import monitor.motion.pack as PK
from monitor.certify import engine

ratios = []
orig = PK._finish
def finish(*a, **k):
    mp = orig(*a, **k)
    if mp.tol[KN.TOL_SCALE] != 0.0:
        pos, _ = PK.body_poses(mp, mp.times)
        nbody = mp.nbody
        mp0 = mp._replace(tol=mp.tol.copy()); mp0.tol[KN.TOL_SCALE] = 0.0
        tr = np.empty((1, nbody))
        KN.batch(mp0, KN.BATCH_BOUNDS, mp.times[:1].copy(), mp.times[-1:].copy(), np.empty((1, nbody, 3)),
                 np.empty((1, nbody, 3, 3)), tr, np.empty((1, nbody)))
        rho = float(np.linalg.norm(mp.ref_points, axis=-1).max())
        old = float(np.linalg.norm(pos, axis=-1).max()) + rho + max(float(tr.max()), 0.0) + 2.0 * rho
        ratios.append(mp.tol[KN.TOL_SCALE] / old)
        if "--old" in sys.argv:
            mp.tol[KN.TOL_SCALE] = old
    return mp
PK._finish = finish
golden = json.loads(T.GOLDEN.read_text())
engine._SWEPT_FIRST = False
names = {"rot-box-box-graze-1e-03/auto/0.01", "rot-box-box-graze-1e-03/toleranced/0.01",
         "rot-hull-box-graze-1e-03/auto/0.01", "rot-hull-box-graze-1e-03/toleranced/0.01", "boxes/6/toleranced"}
for name, run in calls():
    if name not in names:
        continue
    ratios.clear()
    got = json.loads(json.dumps(_summary(run())))
    print(name, "matches recording" if T._first_difference(got, golden[name]) is None else
          "differs: " + T._first_difference(got, golden[name]), "new/old scale:",
          [round(r, 3) for r in ratios][:4])
