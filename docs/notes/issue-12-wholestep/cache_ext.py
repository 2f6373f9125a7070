"""Whether numba caches a function calling MuJoCo's ``mj_step`` as an ``ExternalFunction``.

Usage (twice, the same empty cache dir; the second run should report a cache hit):
    NUMBA_CACHE_DIR=/tmp/<you>/nbc PYTHONPATH=$PWD python docs/notes/issue-12-wholestep/cache_ext.py
"""
from __future__ import annotations

import glob
import os
import time

import llvmlite.binding as llvm
import mujoco
import numba as nb

LIB = sorted(glob.glob(os.path.join(os.path.dirname(mujoco.__file__), "libmujoco.so*")))[0]
llvm.load_library_permanently(LIB)
mj_step = nb.types.ExternalFunction("mj_step", nb.types.void(nb.types.uint64, nb.types.uint64))


@nb.njit(cache=True)
def step_n(m_addr, d_addr, n):
    for _ in range(n):
        mj_step(m_addr, d_addr)


if __name__ == "__main__":
    m = mujoco.MjModel.from_xml_path("models/tunnel/scene.xml")
    d = mujoco.MjData(m)
    t = time.perf_counter()
    step_n(m._address, d._address, 3)
    print(f"first call {time.perf_counter() - t:.3f} s; data.time {d.time:.2f}; cache hits "
          f"{dict(step_n.stats.cache_hits)}, misses {dict(step_n.stats.cache_misses)}")
