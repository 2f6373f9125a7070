"""Cold (first call: scene pack + motion pack + pack check) and warm certify times, sparse scaling scenes.

Usage: PYTHONPATH=$PWD /work/main/.venv/bin/python scripts/measure_sparse_scaling.py
[--profile translating|rotating]
Prints per (motion, n): the first call on a fresh Scene and BodyMotion (what ``bench --suite scaling``
times at 1000 bodies) and the median of 15 (7 at 1000) warm calls; then the warm log-log exponent.
"""

from __future__ import annotations

import cProfile
import pstats
import statistics
import sys
import time

import numpy as np

import monitor
from monitor.bench.suites import scaling_scene
from monitor.certify.common import Budget


def make(n: int, motion: str):
    """A fresh Scene (pairs='all') and BodyMotion of ``n`` sparse boxes."""
    model, bm = scaling_scene(n, "sparse", motion)
    return monitor.Scene.from_model(model, pairs="all"), bm


def timed(scene, bm) -> float:
    """Wall time (ms) of one certify call."""
    t = time.perf_counter()
    monitor.certify(scene, bm, epsilon=1e-3, budget=Budget(seconds=60))
    return 1e3 * (time.perf_counter() - t)


def main() -> None:
    """Print the table (and a cProfile of one cold 1000-body call with --profile)."""
    for motion in ("translating", "rotating"):
        warm = {}
        for n in (10, 100, 1000):
            scene, bm = make(n, motion)
            first = timed(scene, bm)
            warm[n] = statistics.median(timed(scene, bm) for _ in range(15 if n < 1000 else 7))
            print(f"{motion} n={n}: first {first:.3f} ms, warm median {warm[n]:.3f} ms")
        slope = np.polyfit(np.log10([10, 100, 1000]), np.log10([warm[n] for n in (10, 100, 1000)]), 1)[0]
        print(f"{motion}: warm exponent {slope:.3f}")
    if "--profile" in sys.argv:
        motion = sys.argv[sys.argv.index("--profile") + 1]
        scene, bm = make(1000, motion)
        prof = cProfile.Profile()
        prof.enable()
        monitor.certify(scene, bm, epsilon=1e-3)
        prof.disable()
        pstats.Stats(prof).sort_stats("tottime").print_stats(20)


if __name__ == "__main__":
    main()
