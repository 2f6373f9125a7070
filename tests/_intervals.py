"""Interval-union helpers shared by the kernel tests (tests/test_adaptive.py, tests/test_longwindow.py)."""

from __future__ import annotations


def minus(U, V):
    """Pieces of the interval union U not covered by the union V (both sorted, disjoint)."""
    out = []
    for a, b in U:
        cur = a
        for c, d in V:
            if d <= cur or c >= b:
                continue
            if c > cur:
                out.append((cur, c))
            cur = max(cur, d)
        if cur < b:
            out.append((cur, b))
    return out
