"""The typed request of one certification: :class:`CertifyRequest` (issue 12, item 6).

One frozen object holds everything that decides a certificate besides the scene and the
motion: margin, epsilon, the checker (:class:`~monitor.certify.types.Method`), the window,
the work budget, the pair subset, the numerical tolerances and the ongoing-contact rule.
It is validated once, when it is made (:class:`~monitor.errors.InvalidInputError` naming
the field), so a caller that certifies many windows with the same settings (the gate, a
rollout loop, ``review --verify``) validates them once, not per call.

* :func:`monitor.certify.certify` builds one from its keyword arguments, or takes one as
  ``request=``; the :class:`~monitor.certify.certificate.Certificate` carries it
  (``cert.request``).
* The gate builds one per setting and the MCAP log stores it (:meth:`CertifyRequest.to_json`);
  ``review --verify`` rebuilds it with :meth:`CertifyRequest.from_json`.

The budget is held as limits (:class:`BudgetLimits`), not as a running clock:
:meth:`CertifyRequest.new_budget` starts a fresh :class:`~monitor.certify.common.Budget`
for each call.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass, field, fields, replace
from typing import Any

from monitor.certify import common as _common
from monitor.certify.common import Budget
from monitor.certify.ongoing import DEFAULT_PENETRATION_TOL, MAX_PENETRATION_TOL, ONGOING_RULES
from monitor.certify.types import Method, as_method
from monitor.errors import InvalidInputError
from monitor.tolerances import DEFAULT, Tolerances

DEFAULT_EPSILON = 1e-3
"""Default termination tolerance (m of body motion): the toleranced checker stops splitting
a sub-interval once its ball radius times the body's largest lever is below it."""


def _real(owner: str, name: str, v: Any) -> float:
    """``v`` as a finite float, else InvalidInputError naming ``owner.name``."""
    if isinstance(v, bool) or not isinstance(v, numbers.Real):
        raise InvalidInputError(f"{owner}.{name} must be a real number, got {v!r}")
    x = float(v)
    if not math.isfinite(x):
        raise InvalidInputError(f"{owner}.{name} must be finite, got {x}")
    return x


@dataclass(frozen=True)
class BudgetLimits:
    """Work limits of one ``certify`` call; ``None`` is unlimited.

    Attributes:
        seconds: wall seconds (numba compile time not counted), finite and >= 0.
        tests: elementary tests (feature-pair tests, null-set LPs), an integer >= 0.
    """

    seconds: float | None = None
    tests: int | None = None

    def __post_init__(self) -> None:
        if self.seconds is not None:
            s = _real("budget", "seconds", self.seconds)
            if s < 0:
                raise InvalidInputError(f"budget.seconds must be >= 0, got {s}")
            object.__setattr__(self, "seconds", s)
        if self.tests is not None:
            n = self.tests
            if isinstance(n, bool) or not isinstance(n, numbers.Integral):
                raise InvalidInputError(f"budget.tests must be an integer or None, got {n!r}")
            if int(n) < 0:
                raise InvalidInputError(f"budget.tests must be >= 0, got {n!r}")
            object.__setattr__(self, "tests", int(n))

    @classmethod
    def of(cls, budget: Any) -> BudgetLimits:
        """Limits from None (the engine's default seconds), a dict, a BudgetLimits or a Budget's limits."""
        if budget is None:
            return cls(seconds=_common.DEFAULT_BUDGET_SECONDS)
        if isinstance(budget, BudgetLimits):
            return budget
        if isinstance(budget, Budget):
            return cls(seconds=budget.seconds, tests=budget.tests)
        if isinstance(budget, dict):
            unknown = sorted(set(budget) - {"seconds", "tests"}, key=str)
            if unknown:
                raise InvalidInputError(f"budget has unknown field(s) {unknown}; expected 'seconds', 'tests'")
            return cls(seconds=budget.get("seconds"), tests=budget.get("tests"))
        raise InvalidInputError(f"budget must be None, a dict, BudgetLimits or Budget, "
                                f"got {type(budget).__name__}")


@dataclass(frozen=True)
class CertifyRequest:
    """What to certify a motion against, validated once (issue 12, item 6).

    Attributes:
        margin: clearance (m) that counts as safe, finite and >= 0; a distance below it
            is a violation.
        epsilon: termination tolerance (m of body motion), finite and > 0.
        method: the checker (:class:`Method`; its string is accepted and converted).
        window: (t0, t1) seconds with t1 > t0, or None for the motion's whole span
            (checked against the motion's span by ``certify``).
        budget: :class:`BudgetLimits` (a dict or None is converted; None = the engine's
            default wall seconds).
        pairs: subset of candidate pairs as (geom_a, geom_b) name tuples, or None for all
            (checked against the scene by ``certify``).
        tolerances: the numerical :class:`~monitor.tolerances.Tolerances`.
        ongoing: ``"violation"`` or ``"deepen"`` (:mod:`monitor.certify.ongoing`).
        penetration_tol: metres of penetration an ongoing contact may reach, finite > 0.

    Raises:
        InvalidInputError: a field out of its range or of the wrong type (the message
            names the field).
    """

    margin: float = 0.0
    epsilon: float = DEFAULT_EPSILON
    method: Method = Method.AUTO
    window: tuple[float, float] | None = None
    budget: BudgetLimits = field(default_factory=lambda: BudgetLimits.of(None))
    pairs: tuple[tuple[str, str], ...] | None = None
    tolerances: Tolerances = DEFAULT
    ongoing: str = "violation"
    penetration_tol: float = DEFAULT_PENETRATION_TOL

    def __post_init__(self) -> None:
        own = "CertifyRequest"
        margin = _real(own, "margin", self.margin)
        if margin < 0:
            raise InvalidInputError(f"{own}.margin must be >= 0, got {margin}")
        epsilon = _real(own, "epsilon", self.epsilon)
        if epsilon <= 0:
            raise InvalidInputError(f"{own}.epsilon must be > 0, got {epsilon}")
        object.__setattr__(self, "margin", margin)
        object.__setattr__(self, "epsilon", epsilon)
        object.__setattr__(self, "method", as_method(self.method, f"{own}.method"))
        if self.window is not None:
            try:
                t0, t1 = self.window
            except (TypeError, ValueError):
                raise InvalidInputError(f"{own}.window must be (t0, t1) or None, "
                                        f"got {self.window!r}") from None
            t0, t1 = _real(own, "window[0]", t0), _real(own, "window[1]", t1)
            if not t1 > t0:
                raise InvalidInputError(f"{own}.window is empty: t1 = {t1} must be > t0 = {t0}")
            object.__setattr__(self, "window", (t0, t1))
        object.__setattr__(self, "budget", BudgetLimits.of(self.budget))
        if self.pairs is not None:
            if isinstance(self.pairs, str | bytes):
                raise InvalidInputError(f"{own}.pairs must be a sequence of (geom_a, geom_b), "
                                        f"got {self.pairs!r}")
            out = []
            for k, pr in enumerate(self.pairs):
                try:
                    a, b = pr
                except (TypeError, ValueError):
                    raise InvalidInputError(f"{own}.pairs[{k}] must be a (geom_a, geom_b) name pair, "
                                            f"got {pr!r}") from None
                if not isinstance(a, str) or not isinstance(b, str):
                    raise InvalidInputError(f"{own}.pairs[{k}] must hold two geom names, got {pr!r}")
                out.append((a, b))
            object.__setattr__(self, "pairs", tuple(out))
        if not isinstance(self.tolerances, Tolerances):
            raise InvalidInputError(f"{own}.tolerances must be a Tolerances, "
                                    f"got {type(self.tolerances).__name__}")
        if self.ongoing not in ONGOING_RULES:
            raise InvalidInputError(f"{own}.ongoing must be one of {ONGOING_RULES}, got {self.ongoing!r}")
        pen = _real(own, "penetration_tol", self.penetration_tol)
        if not 0 < pen <= MAX_PENETRATION_TOL:
            raise InvalidInputError(f"{own}.penetration_tol must be > 0 and <= {MAX_PENETRATION_TOL:g} (m), "
                                    f"got {pen}")
        object.__setattr__(self, "penetration_tol", pen)

    def new_budget(self) -> Any:
        """A fresh :class:`~monitor.certify.common.Budget` with these limits (its clock starts now)."""
        b = self.budget
        # Budget.default is Budget(seconds=...) field for field, without the dataclass init
        return Budget.default(b.seconds) if b.tests is None else Budget(seconds=b.seconds, tests=b.tests)

    def _with_pairs(self, pairs: tuple[tuple[str, str], ...] | None) -> CertifyRequest:
        """A copy with ``pairs`` set, without validating again (internal: the gate's subset calls).

        ``pairs`` must already be what ``__post_init__`` makes of a valid value: a tuple of
        (str, str) tuples (e.g. names taken from ``scene.candidate_pairs``), or None.
        """
        out = object.__new__(type(self))
        out.__dict__.update(self.__dict__)
        out.__dict__["pairs"] = pairs
        return out

    def replace(self, **changes: Any) -> CertifyRequest:
        """A copy with ``changes`` applied (validated again)."""
        return replace(self, **changes)

    def to_json(self) -> dict[str, Any]:
        """A JSON-ready dict (floats, strings, lists); :meth:`from_json` inverts it exactly."""
        tol = {f.name: getattr(self.tolerances, f.name) for f in fields(Tolerances)}
        return {"margin": self.margin, "epsilon": self.epsilon, "method": str(self.method),
                "window": None if self.window is None else list(self.window),
                "budget": {"seconds": self.budget.seconds, "tests": self.budget.tests},
                "pairs": None if self.pairs is None else [list(p) for p in self.pairs],
                "tolerances": tol, "ongoing": self.ongoing, "penetration_tol": self.penetration_tol}

    @classmethod
    def from_json(cls, d: Any) -> CertifyRequest:
        """The request of a :meth:`to_json` dict (e.g. read back from a log).

        Raises:
            InvalidInputError: not a dict, an unknown or missing field, or a field out of range.
        """
        if not isinstance(d, dict):
            raise InvalidInputError(f"a CertifyRequest record must be a dict, got {type(d).__name__}")
        names = {f.name for f in fields(cls)}
        unknown = sorted(set(d) - names, key=str)
        if unknown:
            raise InvalidInputError(f"CertifyRequest record has unknown field(s) {unknown}")
        kw = dict(d)
        if "tolerances" in kw:
            tol = kw["tolerances"]
            if not isinstance(tol, dict):
                raise InvalidInputError("CertifyRequest record field 'tolerances' must be a dict")
            tnames = {f.name for f in fields(Tolerances)}
            bad = sorted(set(tol) - tnames, key=str)
            if bad:
                raise InvalidInputError(f"CertifyRequest record tolerances have unknown field(s) {bad}")
            kw["tolerances"] = Tolerances(**tol)
        if kw.get("window") is not None:
            kw["window"] = tuple(kw["window"]) if isinstance(kw["window"], list | tuple) else kw["window"]
        if kw.get("pairs") is not None:
            kw["pairs"] = tuple(tuple(p) if isinstance(p, list | tuple) else p for p in kw["pairs"])
        if "budget" in kw:
            kw["budget"] = BudgetLimits.of(kw["budget"])
        return cls(**kw)


__all__ = ["BudgetLimits", "CertifyRequest", "DEFAULT_EPSILON"]
