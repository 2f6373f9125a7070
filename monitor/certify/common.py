"""Types shared by the two checkers and the engine.

A checker never decides "violation" on its own authority except the exact
extrusion checker; the engine confirms every violation with an exact static
test at the witness time (``monitor.geometry.distance``) before reporting it.
"""

from __future__ import annotations

import enum
import math
import threading
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from monitor.errors import InvalidInputError


class Outcome(enum.StrEnum):
    """A checker's three-way finding for one pair (``PairOutcome.verdict``, ``NullResult.verdict``).

    The checkers' own vocabulary, distinct from the public
    :class:`monitor.certify.types.Verdict`: ``UNRESOLVED`` means "not excluded before
    epsilon / depth / budget", which the engine turns into ``"uncertain"`` or, after an
    exact static test confirms a witness, into ``"violation"``. A StrEnum, so comparisons
    with the plain strings (``o.verdict == "unresolved"``) keep working.
    """

    CERTIFIED = "certified"
    VIOLATION = "violation"
    UNRESOLVED = "unresolved"


_OUTCOMES: dict[str, Outcome] = {o.value: o for o in Outcome}


@dataclass
class PairOutcome:
    """What a checker found for one pair over the window.

    Attributes:
        verdict: an :class:`Outcome` (strings are converted; an unknown one raises
            InvalidInputError): ``"certified"`` (proved clear over the whole window),
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

    def __post_init__(self) -> None:
        o = _OUTCOMES.get(self.verdict) if isinstance(self.verdict, str) else None
        if o is None:
            raise InvalidInputError(f"PairOutcome verdict must be one of {tuple(_OUTCOMES)}, "
                                    f"got {self.verdict!r}")
        self.verdict = o


class _CompileClock:
    """Seconds this process has spent compiling numba kernels (``numba:compile`` events).

    A numba compile (or an on-disk cache load) of a kernel used for the first time runs
    inside whatever call needs it. It is not certification work, so :class:`Budget` does
    not charge it: a budget's clock is wall time minus the compile time since the budget
    started. Nested compile events (a kernel compiling its callees) are counted once,
    from the outermost start to its end. numba compiles under a process-wide lock, so
    one compile runs at a time; a compile on another thread during a budget also pauses
    that budget's clock (harmless: a budget is a work limit, never a soundness argument).
    """

    def __init__(self) -> None:
        self.total = 0.0
        self._depth = 0
        self._t0 = 0.0

    def on_start(self, event: Any) -> None:
        if self._depth == 0:
            self._t0 = time.perf_counter()
        self._depth += 1

    def on_end(self, event: Any) -> None:
        self._depth = max(self._depth - 1, 0)
        if self._depth == 0:
            self.total += time.perf_counter() - self._t0

    def seconds(self) -> float:
        """Compile seconds so far (including a compile still running)."""
        if self._depth > 0:
            return self.total + (time.perf_counter() - self._t0)
        return self.total


def _install_compile_clock() -> _CompileClock:
    clock = _CompileClock()
    try:
        from numba.core import event

        class _Listener(event.Listener):
            def on_start(self, ev: Any) -> None:
                clock.on_start(ev)

            def on_end(self, ev: Any) -> None:
                clock.on_end(ev)

        event.register("numba:compile", _Listener())
    except Exception:  # noqa: BLE001 - no numba event API: compile time is charged (slower, never unsound)
        pass
    return clock


COMPILE_CLOCK = _install_compile_clock()
"""Process-wide numba compile time; see :class:`_CompileClock`."""


def compile_seconds() -> float:
    """Seconds this process has spent compiling numba kernels so far."""
    return COMPILE_CLOCK.seconds()


DEFAULT_BUDGET_SECONDS = 10.0
"""Wall-clock budget (s) of a ``certify`` call made with ``budget=None``.

Every call is bounded: a plan with absurd motion (a joint jumping 1e8 rad in one window)
or a huge chain ends "uncertain" after about this long instead of running for minutes.
Pass an explicit :class:`Budget` to choose another limit (``Budget()`` with both fields
None is unlimited, at the caller's risk)."""


class BudgetExhausted(Exception):  # noqa: N818 - a control-flow signal, not an error
    """Raised inside a certify stage when the active budget runs out (internal).

    The engine catches it and reports every unfinished pair "uncertain"; it never leaves
    ``monitor.certify``.
    """


@dataclass
class Budget:
    """Work limit per ``certify`` call: wall seconds and/or elementary tests.

    An exhausted budget turns every unfinished pair into "uncertain", never into
    "certified". ``None`` fields are unlimited. The clock starts when the Budget is
    created (a dict budget or the default one is created when ``certify`` starts) and
    does not count numba compile time (:func:`compile_seconds`): a kernel compiled on
    first use inside a call does not spend that call's budget.
    ``monitor.certify`` checks it inside every stage (motion bounds, broad phase, start
    pose, checkers, witness search); the worst overrun measured is in
    ``docs/notes/issue-11-model.md``.

    Raises:
        InvalidInputError: ``seconds`` not a finite number >= 0, or ``tests`` not an
            integer >= 0 (the message names the field).
    """

    seconds: float | None = None
    tests: int | None = None
    _start: float = field(default_factory=time.perf_counter, repr=False)
    _used_tests: int = field(default=0, repr=False)
    _compile0: float = field(default_factory=compile_seconds, repr=False)

    def __post_init__(self) -> None:
        from monitor.errors import InvalidInputError

        s = self.seconds
        if type(s) is float and 0.0 <= s < math.inf and self.tests is None:
            return          # the default budget's case: a finite float >= 0, no test limit (as below)
        if self.seconds is not None:
            if isinstance(s, bool) or not isinstance(s, int | float | np.integer | np.floating):
                raise InvalidInputError(f"budget seconds must be a number or None, got {s!r}")
            if not math.isfinite(float(s)) or float(s) < 0:
                raise InvalidInputError(f"budget seconds must be finite and >= 0, got {s!r}")
            self.seconds = float(s)
        if self.tests is not None:
            n = self.tests
            if isinstance(n, bool) or not isinstance(n, int | np.integer):
                raise InvalidInputError(f"budget tests must be an integer or None, got {n!r}")
            if int(n) < 0:
                raise InvalidInputError(f"budget tests must be >= 0, got {n!r}")
            self.tests = int(n)

    @classmethod
    def default(cls, seconds: float = 10.0) -> Budget:
        """``Budget(seconds=seconds)``, field for field, without the dataclass init.

        The budget of every ``certify(..., budget=None)`` call (``seconds`` =
        :data:`DEFAULT_BUDGET_SECONDS`). A finite float >= 0 has nothing to validate
        (``__post_init__`` returns at once for it); anything else goes through the
        constructor. The clock fields are read in the same order as the generated
        ``__init__`` reads them.
        """
        if not (type(seconds) is float and 0.0 <= seconds < math.inf):
            return cls(seconds=seconds)
        b = object.__new__(cls)
        b.__dict__.update(seconds=seconds, tests=None, _start=time.perf_counter(),
                          _used_tests=0, _compile0=COMPILE_CLOCK.seconds())
        return b

    def charge(self, tests: int) -> None:
        """Record ``tests`` more elementary tests."""
        self._used_tests += int(tests)

    @property
    def exhausted(self) -> bool:
        """True once either limit is reached."""
        if self.tests is not None and self._used_tests >= self.tests:
            return True
        if self.seconds is None:
            return False
        # = self.elapsed() >= self.seconds, inlined (polled several times per certify call)
        return (time.perf_counter() - self._start - (COMPILE_CLOCK.seconds() - self._compile0)
                >= self.seconds)

    def elapsed(self) -> float:
        """Seconds since the budget started, minus the numba compile time in that span."""
        return time.perf_counter() - self._start - (compile_seconds() - self._compile0)

    def share_clock(self, other: Budget) -> None:
        """Run on ``other``'s clock and test count (a budget derived from ``other``)."""
        self._start = other._start
        self._compile0 = other._compile0
        self._used_tests = other._used_tests

    def check(self) -> None:
        """Raise :class:`BudgetExhausted` if the budget is exhausted."""
        if self.exhausted:
            raise BudgetExhausted


_ACTIVE = threading.local()


class active_budget:  # noqa: N801 - used as a function: ``with active_budget(b): ...``
    """Make ``budget`` the calling thread's active budget inside the ``with`` block.

    Work that cannot take a budget argument (``Trajectory.motion_bounds`` /
    ``body_poses`` of the motion protocol) polls it with :func:`check_active_budget`.
    The previous active budget is restored on exit (also on an exception). A plain class
    rather than a ``contextmanager`` generator: it is entered on every ``certify`` call.
    """

    __slots__ = ("_budget", "_prev")

    def __init__(self, budget: Budget | None) -> None:
        self._budget = budget
        self._prev = None

    def __enter__(self) -> None:
        self._prev = getattr(_ACTIVE, "budget", None)
        _ACTIVE.budget = self._budget

    def __exit__(self, *exc: object) -> None:
        _ACTIVE.budget = self._prev


def check_active_budget() -> None:
    """Raise :class:`BudgetExhausted` if the thread's active budget is exhausted (cheap)."""
    b = getattr(_ACTIVE, "budget", None)
    if b is not None and b.exhausted:
        raise BudgetExhausted


__all__ = ["PairOutcome", "Budget", "Outcome", "BudgetExhausted", "DEFAULT_BUDGET_SECONDS", "compile_seconds",
           "active_budget", "check_active_budget"]
