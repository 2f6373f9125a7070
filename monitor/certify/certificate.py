"""Result objects of a certification: :class:`Certificate`, :class:`PairResult`, :class:`Witness`.

Three verdicts, never collapsed (:class:`~monitor.certify.types.Verdict`, a StrEnum:
``Verdict.CERTIFIED == "certified"``, and JSON, ``str`` and f-strings give the plain string):

* ``"certified"``: for every instant of the window, every candidate pair's
  clearance exceeds ``margin`` (rounding padded). Holds for the continuous motion.
* ``"violation"``: an exact static test at ``witness.time`` confirmed that the
  pair's distance is below ``margin`` (overlap or too close).
* ``"uncertain"``: neither could be shown before epsilon, the depth cap or the
  budget ran out.

Combination over pairs: any violation -> ``"violation"`` (the earliest witness
wins); else any uncertain -> ``"uncertain"``; else ``"certified"``.
All times are seconds of simulation time; points are world-frame metres.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from monitor._json import finite_or, jsonable
from monitor.certify.types import Method, Verdict, as_method, as_verdict
from monitor.errors import InvalidInputError

VERDICTS: tuple[str, ...] = tuple(v.value for v in Verdict)
_RANK = {Verdict.CERTIFIED: 0, Verdict.UNCERTAIN: 1, Verdict.VIOLATION: 2}


def _f(x: float | None) -> float | None:
    """JSON-safe float: NaN -> None, +-inf -> +-1e308 (JSON has no inf)."""
    return None if x is None else finite_or(x, "clamp")


@dataclass(frozen=True)
class Witness:
    """A confirmed violation.

    Attributes:
        time: simulation time (s) of the confirmed violation.
        geoms: (geom_a, geom_b) names.
        point: (3,) world-frame point (m) in or between the two shapes at ``time``.
        distance: exact signed static distance (m) of the pair at ``time``
            (negative = penetration), rounding padded upwards; ``distance < margin``.
    """

    time: float
    geoms: tuple[str, str]
    point: np.ndarray
    distance: float

    def to_dict(self) -> dict[str, Any]:
        """JSON-serialisable form."""
        return {"time": _f(self.time), "geoms": list(self.geoms),
                "point": [float(v) for v in np.asarray(self.point, float).reshape(3)],
                "distance": _f(self.distance)}

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> Witness:
        """Inverse of :meth:`to_dict`."""
        return cls(float(d["time"]), (str(d["geoms"][0]), str(d["geoms"][1])),
                   np.asarray(d["point"], dtype=np.float64).reshape(3),
                   float(d["distance"]) if d.get("distance") is not None else float("nan"))


@dataclass(frozen=True)
class PairResult:
    """Outcome for one candidate geom pair.

    Attributes:
        geoms: (geom_a, geom_b) names.
        bodies: (body_a, body_b) names.
        verdict: a :class:`Verdict` (``"certified" | "violation" | "uncertain"``); a string
            given to the constructor is converted, an unknown one raises InvalidInputError.
        method: checker that decided: ``"culled"`` (broad phase), ``"toleranced"``,
            ``"extrusion"``, or ``"static"`` (start-pose overlap).
        tests: number of elementary tests (toleranced) or LP/null tests (extrusion).
        max_depth: deepest subdivision level reached.
        intervals: ((t_lo, t_hi), ...) sub-intervals (s) where a violation could not
            be excluded; empty when certified.
        clearance: certified lower bound (m) on the pair's distance over the window
            (may be <= 0 or -inf when unknown).
        witness: :class:`Witness` if verdict is ``"violation"``.
        note: ``""``, or why the pair was judged by a special rule, e.g.
            ``"ongoing contact: penetration <= 0.005 m"`` (see
            :mod:`monitor.certify.ongoing`); notes of that rule start with ``"ongoing"``.
    """

    geoms: tuple[str, str]
    bodies: tuple[str, str]
    verdict: Verdict
    method: str
    tests: int = 0
    max_depth: int = 0
    intervals: tuple[tuple[float, float], ...] = ()
    clearance: float = float("-inf")
    witness: Witness | None = None
    note: str = ""

    def __post_init__(self) -> None:
        object.__setattr__(self, "verdict", as_verdict(self.verdict, "PairResult verdict"))

    def to_dict(self) -> dict[str, Any]:
        """JSON-serialisable form (``note`` only when non-empty; plain strings, no enums)."""
        out = {"geoms": list(self.geoms), "bodies": list(self.bodies), "verdict": str(self.verdict),
               "method": self.method, "tests": int(self.tests), "max_depth": int(self.max_depth),
               "intervals": [[float(a), float(b)] for a, b in self.intervals],
               "clearance": _f(self.clearance),
               "witness": self.witness.to_dict() if self.witness else None}
        if self.note:
            out["note"] = self.note
        return out

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> PairResult:
        """Inverse of :meth:`to_dict`."""
        c = d.get("clearance")
        return cls((str(d["geoms"][0]), str(d["geoms"][1])),
                   (str(d["bodies"][0]), str(d["bodies"][1])), d["verdict"], d["method"],
                   int(d.get("tests", 0)), int(d.get("max_depth", 0)),
                   tuple((float(a), float(b)) for a, b in d.get("intervals", [])),
                   float("-inf") if c is None else float(c),
                   Witness.from_dict(d["witness"]) if d.get("witness") else None, str(d.get("note", "")))


class _PairsField:
    """Descriptor of :attr:`Certificate.pairs`: a tuple of :class:`PairResult`, built on first read.

    The engine's compiled path hands the certificate a source object with a
    ``build_pairs()`` method (arrays per pair, no Python object per pair); the tuple is
    built from it the first time ``pairs`` is read and then kept (same content and
    order as an eagerly built tuple). Anything else is stored as a tuple. The
    dataclass machinery sees an ordinary field with default ``()`` (its ``__init__``,
    ``replace``, ``==`` and ``repr`` read and write through this descriptor), and
    ``cert.pairs = x`` still raises ``FrozenInstanceError``.
    """

    def __set_name__(self, owner: type, name: str) -> None:
        self._slot = f"_{name}_store"

    def __get__(self, obj: Any, objtype: type | None = None) -> Any:
        if obj is None:
            return ()
        v = obj.__dict__.get(self._slot, ())
        if not isinstance(v, tuple):
            v = tuple(v.build_pairs())
            obj.__dict__[self._slot] = v
        return v

    def __set__(self, obj: Any, value: Any) -> None:
        if not isinstance(value, tuple) and not hasattr(value, "build_pairs"):
            value = tuple(value)
        obj.__dict__[self._slot] = value


@dataclass(frozen=True)
class Certificate:
    """Result of :func:`monitor.certify` for one window.

    Attributes:
        verdict: combined :class:`Verdict` (see module docstring); a string given to the
            constructor is converted, an unknown one raises InvalidInputError.
        window: (t0, t1) seconds.
        margin: clearance (m) that counts as safe; distance < margin is a violation.
        epsilon: termination tolerance (m of body motion).
        method: requested :class:`Method` (``"auto" | "toleranced" | "extrusion"``); a string
            given to the constructor is converted, an unknown one raises InvalidInputError.
        witness: earliest confirmed violation, or None.
        earliest_time: earliest time (s) at which a violation could not be excluded;
            None when certified.
        clearance: certified lower bound (m) on min clearance over the window.
        pairs: one :class:`PairResult` per candidate pair, in scene order (built on first
            read when the engine's compiled path made the certificate; see :class:`_PairsField`).
        stats: totals, e.g. ``pairs``, ``pairs_culled``, ``tests``, ``max_depth``,
            ``wall_seconds``, ``checker_mix`` ({method: count}).
        allowed: ((geom_a, geom_b, reason), ...) candidate pairs that were NOT checked
            because the allowed-contact matrix allows them (reasons ``Adjacent``,
            ``Default``, ``Always``, ``User``; see :mod:`monitor.acm`), for audit.
        request: the :class:`~monitor.certify.request.CertifyRequest` this certificate
            answers (set by :func:`monitor.certify`; None for a certificate made otherwise,
            e.g. by :meth:`from_dict` or ``dataclasses.replace``). It is not a dataclass
            field, so NOT part of equality, ``repr`` or :meth:`to_dict`: two certificates
            of the same window compare equal whatever request object made them, and logs
            and :meth:`from_dict` are unchanged (a log stores the run's request once, in
            its metadata; see :mod:`monitor.log.writer`).
    """

    verdict: Verdict
    window: tuple[float, float]
    margin: float
    epsilon: float
    method: Method
    witness: Witness | None
    earliest_time: float | None
    clearance: float
    pairs: tuple[PairResult, ...] = _PairsField()  # type: ignore[assignment]
    stats: dict[str, Any] = field(default_factory=dict)
    allowed: tuple[tuple[str, str, str], ...] = ()
    # Not a dataclass field (no annotation): outside __init__, ==, repr, to_dict and replace().
    # monitor.certify sets it in the instance's __dict__ (the dataclass is frozen).
    request = None

    @classmethod
    def _trusted(cls, verdict: Verdict, window: tuple[float, float], margin: float, epsilon: float,
                 method: Method, witness: Witness | None, earliest_time: float | None, clearance: float,
                 pairs: Any, stats: dict[str, Any], allowed: tuple) -> Certificate:
        """The same Certificate as the constructor makes, for the engine's validated values.

        ``verdict`` must already be a :class:`Verdict` and ``method`` a :class:`Method` (what
        ``__post_init__`` would make of them); ``pairs`` a tuple or a lazy object with
        ``build_pairs`` (what :class:`_PairsField` stores). Skips the frozen dataclass's
        per-field ``object.__setattr__`` and the conversions.
        """
        c = object.__new__(cls)
        c.__dict__.update(verdict=verdict, window=window, margin=margin, epsilon=epsilon, method=method,
                          witness=witness, earliest_time=earliest_time, clearance=clearance,
                          _pairs_store=pairs, stats=stats, allowed=allowed)
        return c

    @property
    def ongoing(self) -> tuple[tuple[str, str], ...]:
        """Pairs judged by the ongoing-contact rule (in contact at the window start)."""
        return tuple(p.geoms for p in self.pairs if p.note.startswith("ongoing"))

    def __post_init__(self) -> None:
        object.__setattr__(self, "verdict", as_verdict(self.verdict))
        object.__setattr__(self, "method", as_method(self.method, "Certificate method"))

    def pair_methods(self) -> np.ndarray:
        """(P,) object array of ``str(p.method)`` for each pair of :attr:`pairs`, in order.

        Without building the :class:`PairResult` tuple when the engine's compiled path left
        it unbuilt (the gate reads this every step for ``info["safety"]["checker"]``).
        """
        v = self.__dict__.get("_pairs_store", ())
        if not isinstance(v, tuple) and hasattr(v, "methods"):
            return v.methods()
        names = [str(p.method) for p in self.pairs]
        out = np.empty(len(names), dtype=object)
        out[:] = names
        return out

    @property
    def certified(self) -> bool:
        """True only for the verdict ``"certified"``."""
        return self.verdict == Verdict.CERTIFIED

    def to_dict(self) -> dict[str, Any]:
        """JSON-serialisable form (``json.dumps`` works on it directly; plain strings, no enums)."""
        return {"verdict": str(self.verdict), "window": [float(self.window[0]), float(self.window[1])],
                "margin": float(self.margin), "epsilon": float(self.epsilon), "method": str(self.method),
                "witness": self.witness.to_dict() if self.witness else None,
                "earliest_time": _f(self.earliest_time), "clearance": _f(self.clearance),
                "pairs": [p.to_dict() for p in self.pairs],
                "stats": _jsonable(self.stats),
                **({"allowed": [list(a) for a in self.allowed]} if self.allowed else {})}

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> Certificate:
        """Inverse of :meth:`to_dict`; raises InvalidInputError on malformed input."""
        try:
            c = d.get("clearance")
            return cls(d["verdict"], (float(d["window"][0]), float(d["window"][1])),
                       float(d["margin"]), float(d["epsilon"]), str(d["method"]),
                       Witness.from_dict(d["witness"]) if d.get("witness") else None,
                       None if d.get("earliest_time") is None else float(d["earliest_time"]),
                       float("-inf") if c is None else float(c),
                       tuple(PairResult.from_dict(p) for p in d.get("pairs", [])),
                       dict(d.get("stats", {})),
                       tuple((str(a), str(b), str(r)) for a, b, r in d.get("allowed", [])))
        except InvalidInputError:  # already names the field (unknown verdict / method)
            raise
        except (KeyError, TypeError, IndexError, ValueError) as exc:
            raise InvalidInputError(f"malformed certificate dict: {exc!r}") from exc


def combine_verdicts(verdicts: list[str] | tuple[str, ...]) -> Verdict:
    """Worst verdict: violation > uncertain > certified (certified if empty); strings accepted."""
    worst = Verdict.CERTIFIED
    for v in verdicts:
        v = as_verdict(v)
        if _RANK[v] > _RANK[worst]:
            worst = v
    return worst


def _jsonable(x: Any) -> Any:
    return jsonable(x, "clamp")


def nothing_checked_stats(wall_seconds: float) -> dict[str, Any]:
    """``Certificate.stats`` of a window with no candidate pair to check (verdict ``certified``).

    :func:`monitor.certify` returns it for an empty selection; ``Gate._certify_nothing`` builds the same
    certificate without a Plan (``tests/test_gate_zero_pairs.py`` compares the two).
    """
    return {"pairs": 0, "pairs_culled": 0, "tests": 0, "max_depth": 0, "wall_seconds": wall_seconds,
            "checker_mix": {}, "budget_exhausted": False, "nothing_checked": True}


__all__ = ["Certificate", "Method", "PairResult", "Witness", "Verdict", "VERDICTS", "combine_verdicts",
           "nothing_checked_stats"]

