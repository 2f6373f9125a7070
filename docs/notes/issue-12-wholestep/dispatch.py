"""numba's entry cost from Python by argument count, against one tunnel ``mj_step``.

Usage: PYTHONPATH=$PWD python docs/notes/issue-12-wholestep/dispatch.py CALLS ROUNDS

Interleaved blocks (order rotated per round): a compiled no-op called with k float64 arrays of shape (3,)
(k = 1, 4, 8, 16, 26), a no-op with one int64 scalar, one ``mujoco.mj_step`` on the tunnel scene
through the bindings (the ungated step there), and ``shell``: the Python a whole-step ``Gate.step``
keeps around one compiled call (cast a list ctrl, shape check, a no-op call with the ctrl and 4
workspace arrays, status test, a ``__slots__`` report, two stats increments).
Medians over ROUNDS of the per-call mean (µs).
"""
from __future__ import annotations

import gc
import statistics
import sys
import time

import mujoco
import numba as nb
import numpy as np

ns = time.perf_counter_ns


@nb.njit
def noop(*args):
    return 0


def main():
    calls, rounds = int(sys.argv[1]), int(sys.argv[2])
    m = mujoco.MjModel.from_xml_path("models/tunnel/scene.xml")
    d = mujoco.MjData(m)
    arrays = [np.zeros(3) for _ in range(26)]

    def noop_k(k):
        a = arrays[:k]
        noop(*a)

        def f():
            t = ns()
            for _ in range(calls):
                noop(*a)
            return (ns() - t) / calls / 1e3
        return f

    def scalar():
        noop(7)
        t = ns()
        for _ in range(calls):
            noop(7)
        return (ns() - t) / calls / 1e3

    def step():
        mujoco.mj_resetDataKeyframe(m, d, 0)
        d.ctrl[:] = 0.0
        t = ns()
        for _ in range(calls):
            mujoco.mj_step(m, d)
        return (ns() - t) / calls / 1e3

    class Report:
        __slots__ = ("verdict", "applied", "rows")

        def __init__(self, verdict, applied, rows):
            self.verdict, self.applied, self.rows = verdict, applied, rows

    stats = {"windows": 0, "certified": 0}
    ws = arrays[:4]

    def shell():
        """The Python a whole-step Gate.step keeps: cast, shape, one 4-array call, status, report, stats."""
        ctrl = [0.5]
        t = ns()
        for _ in range(calls):
            c = np.asarray(ctrl, dtype=np.float64)
            if c.shape != (1,):
                raise ValueError("shape")
            status = noop(c, *ws)
            if status:
                raise RuntimeError("not handled")
            Report("certified", c, ws[0])
            stats["windows"] += 1
            stats["certified"] += 1
        return (ns() - t) / calls / 1e3

    blocks = {"mj_step (tunnel)": step, "noop(int)": scalar, "shell (5 arrays)": shell,
              **{f"noop({k} arrays)": noop_k(k) for k in (1, 4, 8, 16, 26)}}
    names = list(blocks)
    res = {n: [] for n in names}
    for r in range(rounds + 1):
        for n in names[r % len(names):] + names[:r % len(names)]:
            gc.collect()
            gc.disable()
            v = blocks[n]()
            gc.enable()
            if r:
                res[n].append(v)
    for n in names:
        print(f"{n:18s} {statistics.median(res[n]):7.3f} µs   {[round(x, 3) for x in res[n]]}")


if __name__ == "__main__":
    main()
