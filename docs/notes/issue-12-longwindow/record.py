"""Record the window_kernel calls of gated Arm / hand30 episodes (issue 12, long windows).

Usage: PYTHONPATH=$PWD python docs/notes/issue-12-longwindow/record.py {arm|hand} N OUT.pkl

Every stage-0 ``window_kernel`` call (one per certify on the compiled path) is kept with
its packs and arguments, so ``analyse.py`` can replay the same windows on any tree.
"""
import pickle
import sys

import numpy as np

from monitor.certify import kernels as K

which, n, out = sys.argv[1], int(sys.argv[2]), sys.argv[3]
calls = []
_orig = K.window_kernel


def rec(gp, mp, pairs, fixed, moving, route, stage, k0, k1, prm, code, gap, surv, res, sc, sr, info):
    r = _orig(gp, mp, pairs, fixed, moving, route, stage, k0, k1, prm, code, gap, surv, res, sc, sr, info)
    if stage == 0:
        calls.append({"gp": gp, "mp": mp, "pairs": pairs.copy(), "fixed": fixed.copy(), "moving": moving.copy(),
                      "prm": prm.copy(), "T": sc.shape[0], "S": int(r), "code": code.copy(),
                      "surv": surv[:int(r)].copy()})
    return r


K.window_kernel = rec

if which == "arm":
    import gymnasium as gym

    import monitor.envs  # noqa: F401
    from monitor.gym_gate import SafetyGate
    g = SafetyGate(gym.make("monitor/Arm-v0"))
    acts = [g.action_space.sample() for _ in range(200)]
    g.reset(seed=0)
    for k in range(n):
        _, _, term, trunc, _ = g.step(acts[k % len(acts)])
        if term or trunc:
            g.reset(seed=0)
else:
    import mujoco

    from monitor.gate import Gate
    m = mujoco.MjModel.from_xml_path("models/hand30/scene.xml")
    lo, hi = m.actuator_ctrlrange[:, 0], m.actuator_ctrlrange[:, 1]
    targets = np.random.default_rng(0).uniform(lo, hi, size=(64, m.nu))
    gate = Gate(m)
    d = mujoco.MjData(m)
    mujoco.mj_resetData(m, d)
    gate.reset()
    for k in range(n):
        gate.step(d, targets[(k // 10) % 64], nstep=5)
print(which, "recorded", len(calls), "windows")
with open(out, "wb") as f:
    pickle.dump(calls, f)
