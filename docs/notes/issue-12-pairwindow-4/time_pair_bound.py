"""CPU time per pair_bound call on the bench cases' motions (random short sub-intervals).

Usage: PYTHONPATH=<tree> python time_pair_bound.py   -> one line per case: name, K, ns per call
"""
import time

import numpy as np
from numba import njit

from monitor.bench.cases import make_cases
from monitor.errors import InvalidInputError, UnsupportedGeometryError
from monitor.motion import kernel as KN
from monitor.motion.bodymotion import BodyMotion
from monitor.motion.pack import pack_trajectory


@njit(cache=False)
def drive(mp, ba, bb, ta, tb, reps):
    """Call pair_bound reps times over the intervals; returns a checksum."""
    pws = KN.pair_workspace(mp)
    pA, RA, pB, RB = np.empty(3), np.empty((3, 3)), np.empty(3), np.empty((3, 3))
    acc = 0.0
    for _ in range(reps):
        for i in range(ta.shape[0]):
            r = KN.pair_bound(mp, ba, bb, ta[i], tb[i], pA, RA, pB, RB, pws)
            acc += r[0] + r[1]
    return acc


def synthetic(K, rng):
    """World + one free body along K waypoints (random walk in position and orientation)."""
    pos = np.zeros((K, 2, 3))
    pos[:, 1] = np.cumsum(rng.normal(0, 0.01, (K, 3)), axis=0)
    quat = np.zeros((K, 2, 4))
    quat[:, 0, 0] = 1.0
    q = np.cumsum(rng.normal(0, 0.02, (K, 4)), axis=0) + np.array([1.0, 0, 0, 0])
    quat[:, 1] = q / np.linalg.norm(q, axis=1, keepdims=True)
    return BodyMotion(np.linspace(0.0, 0.02 * (K - 1), K), pos, quat)


rng = np.random.default_rng(5)
seen = set()
motions = [(c.name, c.group, c.body_motion()) for c in make_cases(seed=7, quick=True)]
motions += [(f"synthetic K={K}", "synthetic", synthetic(K, rng)) for K in (2, 11, 136)]
for name, group, m in motions:
    try:
        mp = pack_trajectory(m)
    except (UnsupportedGeometryError, InvalidInputError):
        continue
    K = mp.times.shape[0]
    key = (group, K)
    if key in seen:
        continue
    seen.add(key)
    t0, t1 = mp.times[0], mp.times[-1]
    n = 2000
    ln = (t1 - t0) * 10 ** rng.uniform(-4, -1, n)
    ta = rng.uniform(t0, t1 - ln)
    tb = ta + ln
    nb = mp.body_parent.shape[0]
    drive(mp, nb - 1, -1, ta[:2], tb[:2], 1)
    best = []
    for _ in range(7):
        s = time.process_time()
        drive(mp, nb - 1, -1, ta, tb, 5)
        best.append((time.process_time() - s) / (5 * n))
    print(f"{name:32s} K={K:4d} {1e9 * np.median(best):8.0f} ns/call")
