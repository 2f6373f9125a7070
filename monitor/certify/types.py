"""The public vocabularies of a certification: :class:`Verdict` and :class:`Method`.

Both are :class:`enum.StrEnum`: every member *is* its string value, so
``cert.verdict == "certified"``, ``f"{cert.verdict}"``, ``str(cert.verdict)``,
``json.dumps(cert.verdict)`` and dict lookups keyed by the plain string all behave
exactly as with the plain strings used before (logs and JSON are byte-identical).
Only ``repr`` differs (``<Verdict.CERTIFIED: 'certified'>``).

The checkers' internal three-way outcome (``certified | violation | unresolved``) is
:class:`monitor.certify.common.Outcome`; the engine maps ``unresolved`` to ``uncertain``
(or to ``violation`` once an exact static test at a witness time confirms it).
"""

from __future__ import annotations

import enum
from typing import Any

from monitor.errors import InvalidInputError


class Verdict(enum.StrEnum):
    """Verdict of a window (``Certificate.verdict``) or of one pair (``PairResult.verdict``).

    * ``CERTIFIED`` (``"certified"``): every candidate pair's clearance exceeds the margin
      at every instant of the window (continuous motion, rounding padded).
    * ``VIOLATION`` (``"violation"``): an exact static test at the witness time confirmed a
      distance below the margin.
    * ``UNCERTAIN`` (``"uncertain"``): neither could be shown before epsilon, the depth cap
      or the budget ran out. Never collapsed into either of the other two.
    """

    CERTIFIED = "certified"
    VIOLATION = "violation"
    UNCERTAIN = "uncertain"


class Method(enum.StrEnum):
    """Checker requested from :func:`monitor.certify` (``method=``); strings are accepted too.

    * ``AUTO`` (``"auto"``): extrusion for pairs whose bodies both translate with piecewise
      linear motion, toleranced otherwise.
    * ``TOLERANCED`` (``"toleranced"``): Schröcker & Weber toleranced motions for every pair.
    * ``EXTRUSION`` (``"extrusion"``): Cameron 4-D extrusion; every checked pair must translate.
    """

    AUTO = "auto"
    TOLERANCED = "toleranced"
    EXTRUSION = "extrusion"


# Lookup by value (a StrEnum member hashes and compares as its string, so members are keys too).
_VERDICTS: dict[str, Verdict] = {v.value: v for v in Verdict}
_METHODS: dict[str, Method] = {m.value: m for m in Method}


def _member(table: dict, value: Any, name: str) -> Any:
    """The member of ``table`` (string -> enum member) for ``value``, or InvalidInputError naming ``name``."""
    try:
        v = table.get(value)
    except TypeError:  # unhashable
        v = None
    if v is None:
        raise InvalidInputError(f"{name} must be one of {tuple(table)}, got {value!r}")
    return v


def as_verdict(value: Any, name: str = "verdict") -> Verdict:
    """``value`` (a :class:`Verdict` or its string) as a :class:`Verdict`.

    Raises:
        InvalidInputError: ``value`` is not one of the three verdicts; the message names
            the argument ``name`` and the value.
    """
    return _member(_VERDICTS, value, name)


def as_method(value: Any, name: str = "method") -> Method:
    """``value`` (a :class:`Method` or its string) as a :class:`Method`.

    Raises:
        InvalidInputError: ``value`` is not a known method; the message names the argument
            ``name`` and the value (``method must be one of ('auto', 'toleranced',
            'extrusion'), got 'x'``).
    """
    return _member(_METHODS, value, name)


__all__ = ["Method", "Verdict", "as_method", "as_verdict"]
