"""Tunnel Gate.step per step: compiled first pass on vs off (the Python extrusion checker), interleaved.

Usage: PYTHONPATH=<tree> python docs/notes/issue-12-translations/ab_tunnel.py [rounds]
Also times an ungated mj_step loop of the same windows (nstep=1) for the x-ungated ratio.
"""
import sys
import time

import mujoco
import numpy as np

from monitor.certify import engine

sys.path.insert(0, __file__.rsplit("/", 1)[0])
from tunnel import d, m, run  # noqa: E402

rounds = int(sys.argv[1]) if len(sys.argv) > 1 else 6
has_flag = hasattr(engine, "_SWEPT_FIRST")
res: dict[bool, list[float]] = {True: [], False: []}
verdicts = {}
run(5)
for _ in range(rounds):
    for flag in (True, False):
        if has_flag:
            engine._SWEPT_FIRST = flag
        dt, vs = run(100)
        res[flag].append(dt)
        verdicts[flag] = dict(vs)


def ungated(n: int = 100) -> float:
    """Seconds per plain mj_step under the same controller."""
    mujoco.mj_resetDataKeyframe(m, d, 0)
    t = time.perf_counter()
    for k in range(n):
        target = 0.3 if (k // 25) % 2 == 0 else -0.3
        d.ctrl[:] = np.clip([12.0 * (target - d.qpos[0])], -6, 6)
        mujoco.mj_step(m, d)
    return (time.perf_counter() - t) / n


ug = float(np.median([ungated() for _ in range(20)]))
on, off = float(np.median(res[True])), float(np.median(res[False]))
print(f"per step median of {rounds} x 100 steps: compiled-first {1e6 * on:.0f} us, "
      f"python-only {1e6 * off:.0f} us, ratio {off / on:.2f}x; ungated mj_step {1e6 * ug:.2f} us",
      f"-> {on / ug:.0f}x / {off / ug:.0f}x ungated")
print("verdicts", verdicts)
