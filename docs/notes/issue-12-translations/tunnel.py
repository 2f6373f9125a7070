"""Plain Gate.step on models/tunnel (copy of /work/wt/prof/tunnel.py): per-step mean, then a profile.

Usage: PYTHONPATH=<tree> python docs/notes/issue-12-translations/tunnel.py [sortkey]
"""
import collections
import cProfile
import pstats
import sys
import time

import mujoco
import numpy as np

from monitor._paths import scene_path
from monitor.gate import Gate

m = mujoco.MjModel.from_xml_path(str(scene_path("tunnel")))
gate = Gate(m, margin=0.001)
d = mujoco.MjData(m)


def run(n: int) -> tuple[float, collections.Counter]:
    """``n`` gated steps from the keyframe: mean seconds per step and the verdict counts."""
    mujoco.mj_resetDataKeyframe(m, d, 0)
    gate.reset()
    vs: collections.Counter = collections.Counter()
    t = time.perf_counter()
    for k in range(n):
        target = 0.3 if (k // 25) % 2 == 0 else -0.3
        r = gate.step(d, np.clip([12.0 * (target - d.qpos[0])], -6, 6), nstep=1)
        vs[str(r.verdict)] += 1
    return (time.perf_counter() - t) / n, vs


if __name__ == "__main__":
    run(5)
    dt, vs = run(100)
    print("per step us", dt * 1e6, dict(vs))
    if len(sys.argv) > 1:
        pr = cProfile.Profile()
        pr.enable()
        run(100)
        pr.disable()
        pstats.Stats(pr).sort_stats(sys.argv[1]).print_stats(45)
