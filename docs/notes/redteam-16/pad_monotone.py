"""Red team 16, idea (1c): "every pad grows with S" (plan.py, "The rounding scale" (c)).

For random trees (scale_fuzz.chain_xml) and random sub-intervals, the Plan's bounds
(`Plan._bounds`) and the compiled bounds (`batch(BATCH_BOUNDS)` with tol[3] set) at a ladder of
scales S_0 < S_1 < ... must be nondecreasing in S (translations) and constant (angles).
Usage: PYTHONPATH=<tree> python pad_monotone.py N SEED
"""
import sys

import mujoco
import numpy as np

from monitor.motion import kernel as KN
from monitor.motion.pack import pack_trajectory
from monitor.motion.plan import Plan

sys.path.insert(0, __file__.rsplit("/", 1)[0])
from scale_fuzz import chain_xml, rqpos  # noqa: E402


def main(n, seed):
    rng = np.random.default_rng(seed)
    plans = checks = bad_py = bad_k = bad_ang = 0
    for _ in range(n):
        big = 10.0 ** rng.uniform(0, 8)
        try:
            m = mujoco.MjModel.from_xml_string(chain_xml(rng, big))
        except Exception:
            continue
        K = int(rng.integers(2, 12))
        times = np.cumsum(rng.uniform(0.01, 1.0, K))
        plan = Plan(times, rqpos(rng, m, K, tiny=rng.random() < 0.4), model=m)
        if not plan.moving_bodies().any():
            continue
        plans += 1
        N = 6
        a = rng.uniform(times[0], times[-1], N)
        b = np.minimum(a + rng.uniform(0, 1, N) * (times[-1] - a) * rng.choice([1e-9, 1e-3, 1.0], N), times[-1])
        b = np.maximum(b, a)
        ladder = np.sort(np.concatenate([[0.0], 10.0 ** rng.uniform(-3, 9, 5)]))
        mp = pack_trajectory(plan)
        prev_py = prev_k = None
        for S in ladder:
            tr, an = plan._bounds(a.copy(), b.copy(), scale=float(S))
            mps = mp._replace(tol=mp.tol.copy())
            mps.tol[KN.TOL_SCALE] = S
            nb = m.nbody
            tk, ak = np.empty((N, nb)), np.empty((N, nb))
            KN.batch(mps, KN.BATCH_BOUNDS, a.copy(), b.copy(), np.empty((N, nb, 3)), np.empty((N, nb, 3, 3)), tk, ak)
            if prev_py is not None:
                checks += 1
                bad_py += int(np.any(tr < prev_py[0]))
                bad_k += int(np.any(tk < prev_k[0]))
                bad_ang += int(np.any(an != prev_py[1]) or np.any(ak != prev_k[1]))
            prev_py, prev_k = (tr, an), (tk, ak)
    print(f"seed {seed}: plans {plans}, ladder steps {checks} (x6 sub-intervals x nbody), "
          f"Plan bound decreased {bad_py}, kernel bound decreased {bad_k}, angle changed {bad_ang}")


if __name__ == "__main__":
    main(int(sys.argv[1]), int(sys.argv[2]))
