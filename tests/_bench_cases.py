"""The bench's seeded quick case set, built once per test process.

``monitor.bench.cases.make_cases(seed, quick=True)`` costs ~12 s of CPU (placing the near misses)
and several test files read the same set: they share one build. The cases' arrays are made
read-only so a test that tried to edit a shared case fails loudly instead of leaking into another.
"""

import functools

import numpy as np

from monitor.bench.cases import make_cases

QUICK_CASES_GROUP = "bench_quick_cases"
"""``xdist_group`` of the fast tests that read :func:`quick_cases`: one worker builds the set once."""


@functools.cache
def quick_cases(seed: int = 7) -> tuple:
    """``tuple(make_cases(seed=seed, quick=True))`` with every ndarray attribute read-only."""
    cases = tuple(make_cases(seed=seed, quick=True))
    for c in cases:
        for v in vars(c).values():
            for a in (v if isinstance(v, tuple) else (v,)):
                if isinstance(a, np.ndarray):
                    a.setflags(write=False)
    return cases
