"""Dump motion-bound outputs (tree pass and pair_bound) on many random intervals.

For an old/new bit-for-bit comparison of monitor.motion.kernel._bounds_core.

Usage: PYTHONPATH=<tree> python parity_bounds.py OUT.npz   (run once per tree, then
       python parity_bounds.py --compare A.npz B.npz)
Intervals: each segment, whole window, random, endpoints equal to waypoint times, one-ulp
intervals (at, just before and just after waypoint times), zero-length intervals.
"""
import sys

import numpy as np

if sys.argv[1] == "--compare":
    a, b = np.load(sys.argv[2]), np.load(sys.argv[3])
    assert sorted(a.files) == sorted(b.files)
    n = 0
    for k in a.files:
        x, y = a[k], b[k]
        assert x.shape == y.shape and x.tobytes() == y.tobytes(), k
        n += x.size
    print("identical:", len(a.files), "arrays,", n, "numbers")
    sys.exit(0)

sys.path.insert(0, "tests")
from test_motion_kernel import _random_plan  # noqa: E402

from monitor.motion import kernel as KN  # noqa: E402
from monitor.motion.pack import pack_trajectory  # noqa: E402

rng = np.random.default_rng(20261128)
out = {}
for p in range(60):
    m, times, plan = _random_plan(rng)
    mp = pack_trajectory(plan)
    K = times.shape[0]
    iv = [(times[k], times[k + 1]) for k in range(K - 1)] + [(times[0], times[-1])]
    for _ in range(20):
        a, b = np.sort(rng.uniform(times[0], times[-1], 2))
        iv.append((a, b))
    for k in range(K):
        t = times[k]
        iv += [(t, t), (t, np.nextafter(t, np.inf)), (np.nextafter(t, -np.inf), t),
               (np.nextafter(t, -np.inf), np.nextafter(t, np.inf))]
        for j in range(K):
            if j > k:
                iv.append((t, times[j]))
        c = rng.uniform(times[0], times[-1])
        iv += [(c, np.nextafter(c, np.inf)), (c, c), (times[0], t), (t, times[-1]),
               (t, rng.uniform(t, times[-1])), (rng.uniform(times[0], t), t)]
    iv = [(max(a, times[0]), min(b, times[-1])) for a, b in iv]
    iv = [(a, b) for a, b in iv if a <= b]
    t0 = np.array([x[0] for x in iv])
    t1 = np.array([x[1] for x in iv])
    N, nb = t0.shape[0], m.nbody
    pos, rot = np.empty((N, nb, 3)), np.empty((N, nb, 3, 3))
    trans, angle = np.empty((N, nb)), np.empty((N, nb))
    KN.batch(mp, KN.BATCH_BOUNDS, t0, t1, pos, rot, trans, angle)
    out[f"{p}_pos"], out[f"{p}_rot"], out[f"{p}_trans"], out[f"{p}_angle"] = pos, rot, trans, angle
    pws = KN.pair_workspace(mp)
    pr = []
    for i in range(N):
        ba, bb = (int(x) for x in rng.integers(0, nb, 2))
        pa, Ra, pb, Rb = np.empty(3), np.empty((3, 3)), np.empty(3), np.empty((3, 3))
        got = KN.pair_bound(mp, ba, bb, t0[i], t1[i], pa, Ra, pb, Rb, pws)
        pr.append(np.concatenate([np.array(got, dtype=float), pa, Ra.ravel(), pb, Rb.ravel()]))
    out[f"{p}_pair"] = np.array(pr)
    out[f"{p}_t"] = np.stack([t0, t1])
np.savez(sys.argv[1], **out)
print("intervals:", sum(out[k].shape[1] for k in out if k.endswith("_t")))
