"""decide_plan_pair vs decide_pair on waypoint tracks whose segment velocity overflows (merged tree: decide_pair declines)."""
import sys
import numpy as np
from monitor.certify import extrusion_swept as ES
from monitor.geometry.polytope import box_polytope, sphere_shape
from monitor.tolerances import DEFAULT
rng = np.random.default_rng(int(sys.argv[1]))
N = int(sys.argv[2])
cnt = {}
shapes = [lambda: box_polytope(rng.uniform(0.01, 0.3, 3)), lambda: sphere_shape(rng.uniform(0.01, 0.2))]
for it in range(N):
    K = int(rng.integers(2, 5))
    kind = rng.integers(0, 5)
    dts = rng.uniform(0.1, 1.0, K - 1)
    j = rng.integers(0, K - 1)
    if kind == 0: dts[j] = rng.choice([1e-308, 5e-324, 1e-310, 2.2e-308])
    times = np.cumsum(np.r_[rng.uniform(-1, 1), dts])
    nbody = 3
    wp = rng.uniform(-1, 1, (K, nbody, 3))
    if kind == 1: wp[:, 1] *= 9e307          # huge coordinates
    if kind == 2: wp[:, 2, rng.integers(0, 3)] = rng.choice([-1, 1], K) * 1.7e308
    if kind == 3:
        dts[j] = 1e-300; times = np.cumsum(np.r_[0.0, dts]); wp[j + 1, 1] = wp[j, 1] + 5e9
    wp[:, 0] = wp[0, 0]
    ba, bb = [int(x) for x in rng.choice(3, 2, replace=False)]
    ma, mb = ba != 0, bb != 0
    if not ma: wp[:, ba] = wp[0, ba]
    times.setflags(write=False)
    wp = np.ascontiguousarray(wp)
    if rng.random() < .5:
        w0, w1 = times[0], times[-1]
    else:
        w0, w1 = sorted(rng.uniform(times[0], times[-1], 2))
        if not w0 < w1: continue
    sa, sb = shapes[rng.integers(0, 2)](), shapes[rng.integers(0, 2)]()
    margin = float(rng.choice([0.0, 1e-300, 0.01, 1e3]))
    with np.errstate(all="ignore"):
        o1 = ES.decide_plan_pair(sa, sb, np.eye(3), np.eye(3), times, wp, ba, bb, ma, mb, (float(w0), float(w1)), margin, margin + DEFAULT.extrusion_slack + DEFAULT.pad(margin), DEFAULT)
        def seg(b, m):
            return (times[[0, -1]].copy(), wp[[0, 0], b].copy()) if not m else (times.copy(), wp[:, b].copy())
        (ta, oa), (tb, ob) = seg(ba, ma), seg(bb, mb)
        o2 = ES.decide_pair(sa, np.eye(3), ta, oa, sb, np.eye(3), tb, ob, (float(w0), float(w1)), margin, margin + DEFAULT.extrusion_slack + DEFAULT.pad(margin), DEFAULT)
    k = (int(kind), o1 and str(o1.verdict), o2 and str(o2.verdict))
    cnt[k] = cnt.get(k, 0) + 1
    if (o1 is None) != (o2 is None) or (o1 is not None and o1.verdict != o2.verdict):
        if cnt[k] <= 2: print("DIFF", it, k, times.tolist(), (w0, w1), ba, bb, ma, mb, margin, flush=True)
print(cnt)
