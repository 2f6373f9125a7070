"""Prototype (a) with hot caches: best of 5 repeated calls per recorded gate state, and the tail lengths.

Usage: PYTHONPATH=$PWD:$PWD/docs/notes/issue-12-wholestep \
       python docs/notes/issue-12-wholestep/physics_hot.py tunnel|pusher STEPS ROUNDS

States and proposals recorded from the real gate (``proto_time.record_*``). Per step: ``cmj.Physics.run``
(window + braking tail, always) best of 5 calls, one compiled ``mj_step`` window (``cmj.step_n``) best of
5, the tail's length. Prints per verdict of the recording gate: medians, and µs per simulated substep.
"""
from __future__ import annotations

import sys
import time

import mujoco
import numpy as np
import proto_time as PT
from cmj import Physics, step_n

ns = time.perf_counter_ns


def best(f, n=5):
    b = 1 << 62
    for _ in range(n):
        t = ns()
        f()
        b = min(b, ns() - t)
    return b / 1e3


def main():
    which, steps, rounds = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
    m, nstep, gate, recs = (PT.record_tunnel if which == "tunnel" else PT.record_pusher)(steps)
    P = Physics(m, nstep, gate.brake_steps, gate.brake_vel_tol)
    d = mujoco.MjData(m)
    sig = mujoco.mjtState.mjSTATE_INTEGRATION
    for rnd in range(rounds):
        res = {}
        for st, ctrl, _calls, kind, _tb, _ap in recs:
            def run():
                mujoco.mj_setState(m, d, st, sig)
                return P.run(d, ctrl)

            def window():
                mujoco.mj_setState(m, d, st, sig)
                d.ctrl[:] = ctrl
                step_n(m._address, d._address, nstep)
            a = best(run)
            w = best(window)
            tail = len(run()[1]) - 1
            res.setdefault(kind, []).append((a, tail, w))
        for k, r in res.items():
            x = np.array(r)
            print(f"round {rnd} {k} ({len(r)} steps): a {np.median(x[:, 0]):.1f} µs, "
                  f"tail substeps mean "
                  f"{x[:, 1].mean():.2f} (median {int(np.median(x[:, 1]))}), compiled window "
                  f"{np.median(x[:, 2]):.2f} µs, a per substep "
                  f"{np.median(x[:, 0] / (nstep + x[:, 1])):.2f} µs")


if __name__ == "__main__":
    main()
