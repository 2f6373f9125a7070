"""Types shared by the two checkers and the engine.

A checker never decides "violation" on its own authority except the exact
extrusion checker; the engine confirms every violation with an exact static
test at the witness time (``monitor.geometry.distance``) before reporting it.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np

Outcome = Literal["certified", "violation", "unresolved"]


@dataclass
class PairOutcome:
    """What a checker found for one pair over the window.

    Attributes:
        verdict: ``"certified"`` (proved clear over the whole window),
            ``"violation"`` (the checker found a witness: ``witness_time`` and
            ``witness_point`` are set; the engine re-confirms it), or
            ``"unresolved"`` (``intervals`` could not be excluded before epsilon /
            depth / budget).
        tests: elementary tests performed (toleranced: feature-pair tests;
            extrusion: null-set tests / LPs).
        max_depth: deepest subdivision level reached.
        intervals: list of (t_lo, t_hi) seconds that remain possible violations,
            sorted by time.
        clearance: certified lower bound (m) on the pair distance over the
            window, or -inf when not established.
        witness_time: seconds, or None.
        witness_point: (3,) world metres, or None.
        info: checker-specific statistics (JSON-serialisable).
    """

    verdict: Outcome
    tests: int = 0
    max_depth: int = 0
    intervals: list[tuple[float, float]] = field(default_factory=list)
    clearance: float = float("-inf")
    witness_time: float | None = None
    witness_point: np.ndarray | None = None
    info: dict[str, Any] = field(default_factory=dict)


@dataclass
class Budget:
    """Work limit per ``certify`` call: wall seconds and/or elementary tests.

    An exhausted budget turns every unfinished pair into "uncertain", never into
    "certified". ``None`` fields are unlimited.
    """

    seconds: float | None = None
    tests: int | None = None
    _start: float = field(default_factory=time.perf_counter, repr=False)
    _used_tests: int = field(default=0, repr=False)

    def charge(self, tests: int) -> None:
        """Record ``tests`` more elementary tests."""
        self._used_tests += int(tests)

    @property
    def exhausted(self) -> bool:
        """True once either limit is reached."""
        if self.tests is not None and self._used_tests >= self.tests:
            return True
        return self.seconds is not None and time.perf_counter() - self._start >= self.seconds


__all__ = ["PairOutcome", "Budget", "Outcome"]
