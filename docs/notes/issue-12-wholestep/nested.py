"""Whether the engine's kernels can be called from another nopython function (a whole-step kernel needs it).

Usage: PYTHONPATH=$PWD:$PWD/docs/notes/issue-12-wholestep \
       python docs/notes/issue-12-wholestep/nested.py tunnel|pusher STEPS

Records the gate's kernel calls (as ``proto_time.py``); for each kernel, a ``@njit`` wrapper
``call(args) -> kernel(*args)`` taking the recorded arguments as ONE tuple is compiled, called on a
copy and compared with the direct call (every returned array / scalar, bytes, NaN-aware).
"""
from __future__ import annotations

import sys

import numba as nb
import numpy as np
import proto_time as PT


def make(disp):
    @nb.njit
    def call(args):
        return disp(*args)
    return call


def same(x, y):
    if isinstance(x, tuple):
        return isinstance(y, tuple) and len(x) == len(y) and all(same(a, b) for a, b in zip(x, y))
    if isinstance(x, np.ndarray):
        return isinstance(y, np.ndarray) and x.shape == y.shape and x.tobytes() == y.tobytes()
    return x == y or (x != x and y != y)


def main():
    which, steps = sys.argv[1], int(sys.argv[2])
    PT.install()
    _, _, _, recs = (PT.record_tunnel if which == "tunnel" else PT.record_pusher)(steps)
    seen = {}
    for _, _, calls, *_ in recs:
        for disp, a in calls:
            name = disp.py_func.__name__
            r = seen.setdefault(name, [make(disp), 0, 0, None])
            try:
                got = r[0](tuple(PT._copy(a)))
            except Exception as e:  # noqa: BLE001 - report the typing failure
                r[3] = f"{type(e).__name__}: {str(e).splitlines()[0][:120]}"
                continue
            ref = disp(*PT._copy(a))
            r[1] += 1
            r[2] += same(got, ref)
    for name, (_, n, ok, err) in seen.items():
        tail = f"; error {err}" if err else ""
        print(f"{name}: {n} nested calls, {ok} identical to the direct call{tail}")


if __name__ == "__main__":
    main()
