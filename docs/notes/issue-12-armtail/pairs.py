"""Per survivor pair in Arm gate certify calls: tests, code; grouped by plan rows."""
import sys, collections, statistics
import numpy as np, gymnasium as gym
import monitor.envs  # noqa
import monitor.certify.engine as E
import monitor.certify.kernels as KS
from monitor.gym_gate import SafetyGate
cur = {"rows": 0}
stat = collections.defaultdict(list)
_wk = E._window_kernel
def wk(K, gp, mp, pairs, fixed, moving, *rest):
    r = _wk(K, gp, mp, pairs, fixed, moving, *rest)
    route, stage, k0, k1, prm, code, gap, surv, res = rest[:9]
    K_ = mp.times.shape[0]
    if stage == 0:
        stat[(K_, "S")].append(int(r)); stat[(K_, "P")].append(pairs.shape[0])
        lo, hi = 0, min(k1, int(r))
    else:
        lo, hi = k0, k1
    for s in range(lo, hi):
        c = int(code[surv[s]])
        stat[(K_, "tests")].append(int(res[s, KS.R_TESTS])); stat[(K_, "code", c)].append(int(res[s, KS.R_TESTS]))
    return r
E._window_kernel = wk
env = SafetyGate(gym.make("monitor/Arm-v0"))
for ep in range(6):
    env.reset(seed=ep); env.action_space.seed(ep)
    for a in [env.action_space.sample() for _ in range(20)]: env.step(a)
for k in sorted(stat, key=str):
    v = stat[k]
    print(k, "n", len(v), "sum", sum(v), "median", statistics.median(v), "max", max(v))
print({n: getattr(KS, n) for n in dir(KS) if n.startswith("WK_")})
