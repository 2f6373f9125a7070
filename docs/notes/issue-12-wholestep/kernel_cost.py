"""The compiled certify kernels of one gated step: hot cost per call, and how much of it is dispatch.

Usage: PYTHONPATH=$PWD:$PWD/docs/notes/issue-12-wholestep \
       python docs/notes/issue-12-wholestep/kernel_cost.py \
           tunnel|pusher STEPS

Records the kernel calls of STEPS gated steps (as ``proto_time.py``), then per kernel name:
* ``hot``: each recorded call repeated on fresh copies of its arguments, min over 7 x 20 calls (caches hot);
* ``dispatch``: a no-op ``@njit(*args)`` called with the same arguments (same numba types): what
  the Python -> numba entry costs (argument typing and unboxing) before any kernel work;
* per step: calls per step x (hot, dispatch).
"""
from __future__ import annotations

import statistics
import sys
import time
from collections import defaultdict

import numba as nb
import proto_time as PT

ns = time.perf_counter_ns


@nb.njit
def noop(*args):
    return 0


def main():
    which, steps = sys.argv[1], int(sys.argv[2])
    PT.install()
    _, _, _, recs = (PT.record_tunnel if which == "tunnel" else PT.record_pusher)(steps)
    by = defaultdict(list)
    for _, _, calls, *_ in recs:
        for disp, a in calls:
            by[disp.py_func.__name__].append((disp, a))
    print(f"{which}: {len(recs)} steps")
    print(f"{'kernel':22s} {'calls/step':>10s} {'args':>5s} {'hot µs/call':>12s} {'dispatch µs':>12s} "
          f"{'hot µs/step':>12s} {'of which dispatch':>18s}")
    tot_hot = tot_disp = 0.0
    for name, calls in sorted(by.items(), key=lambda kv: -len(kv[1])):
        sample = calls[:: max(1, len(calls) // 60)]  # up to ~60 representative calls
        hot, disp_t = [], []
        for disp, a in sample:
            best = bestn = 1 << 62
            for _ in range(7):
                cs = [PT._copy(a) for _ in range(20)]
                t = ns()
                for c in cs:
                    disp(*c)
                best = min(best, (ns() - t) / 20)
                noop(*cs[0])
                t = ns()
                for c in cs:
                    noop(*c)
                bestn = min(bestn, (ns() - t) / 20)
            hot.append(best / 1e3)
            disp_t.append(bestn / 1e3)
        per_step = len(calls) / len(recs)
        h, dd = statistics.mean(hot), statistics.mean(disp_t)
        tot_hot += per_step * h
        tot_disp += per_step * dd
        print(f"{name:22s} {per_step:10.2f} {len(sample[0][1]):5d} {h:12.2f} {dd:12.2f} {per_step * h:12.2f} "
              f"{per_step * dd:18.2f}")
    print(f"{'total':22s} {'':10s} {'':5s} {'':12s} {'':12s} {tot_hot:12.2f} {tot_disp:18.2f}")


if __name__ == "__main__":
    main()
