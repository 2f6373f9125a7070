"""Kernel-only verdicts and tests on the seeded peers cases (packable ones), for a tree comparison.

Usage: PYTHONPATH=<tree> python docs/notes/issue-12-longwindow/peers.py OUT.json [full]
Each case: pair_window MODE_CERTIFY_ONLY and MODE_FULL, eps 1e-3, margin 0 (as tests/test_adaptive.py packs).
"""
import json
import sys

from monitor.bench.cases import make_cases
from monitor.certify import kernels as K
from monitor.certify.packed import pack_shapes
from monitor.motion.pack import pack_trajectory

out = {}
for c in make_cases(seed=7, quick=len(sys.argv) < 3):
    try:
        mp = pack_trajectory(c.body_motion())
    except Exception:      # screw / Bezier cases: not packable, never reach this kernel
        continue
    gp = pack_shapes([None, *[s.convex_shape() for s in c.shapes]], [0, 1, 2])
    row = []
    for co in (True, False):
        r = K.check_pair_window(gp, mp, 1, 2, (0.0, c.duration), 0.0, 1e-3, certify_only=co)
        row += [r["verdict"], r["tests"]]
    out[c.name] = row
json.dump(out, open(sys.argv[1], "w"), indent=0)
print(len(out), "cases")
