"""All numerical tolerances of `monitor`, in one frozen dataclass.

No algorithm hard-codes an epsilon: it takes a :class:`Tolerances` (default
:data:`DEFAULT`) and uses the named field. Each field says why it has its value.
Lengths are metres, angles radians, times seconds.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass


def _is_real(v: object) -> bool:
    return isinstance(v, numbers.Real) and not isinstance(v, bool)


def _is_integer(v: object) -> bool:
    return isinstance(v, numbers.Integral) and not isinstance(v, bool)


@dataclass(frozen=True)
class Tolerances:
    """Numerical tolerances; every value carries its reason.

    Rounding pads: every radius and threshold that decides "certified" is
    enlarged by ``pad(x) = rel_pad * |x| + abs_pad`` (plus the scene scale term),
    so that float64 rounding in the tests can only push a verdict towards
    "not certified", never towards "certified".

    Where each pad is applied: ``monitor/certify/toleranced.py`` and
    ``monitor/certify/bezier.py`` module docstrings (elementary-test thresholds,
    ball radii, de Casteljau error), ``monitor/motion/plan.py`` (motion bounds),
    ``monitor/geometry/distance.py`` (static bounds) and
    ``monitor/certify/extrusion.py`` (LP slack and witness verification).
    """

    quat_norm_tol: float = 1e-6
    """A waypoint quaternion whose norm differs from 1 by at most this is
    normalised silently; beyond it the plan is rejected. 1e-6 admits float32
    round trips (relative error ~6e-8 per component) and rejects real mistakes."""

    rel_pad: float = 64 * 2.0**-52
    """Relative rounding pad (64 ulp ~ 1.4e-14). Our elementary tests evaluate
    quadratics with a few dozen flops; Higham's gamma_n bound for n<=32
    operations is ~n*u = 32*1.1e-16, doubled for safety."""

    abs_pad: float = 1e-12
    """Absolute pad in metres, added to every clearance threshold. It covers
    cancellation near the origin where a relative pad vanishes; 1e-12 m is far
    below any physical clearance (MuJoCo's own mjMINVAL is 1e-15)."""

    scale_pad: float = 1e-13
    """Pad proportional to the scene's coordinate magnitude (|x|max): points at
    1e4 m carry absolute rounding ~1e4 * 1.1e-16 ~ 1e-12 per operation; 1e-13
    per metre of offset covers ~1000 such operations."""

    max_depth: int = 40
    """Hard cap on subdivision depth. 2^-40 of a 1 s window is ~1 ps: below it
    the motion bound is dominated by rounding, so deeper splits cannot help."""

    facets: int = 16
    """Default facet count of circumscribed polytopes for cylinders and
    ellipsoids. 16 gives a radial over-approximation of r*(1/cos(pi/16)-1) ~ 1.9 %,
    reported per geom in ``Scene``."""

    extrusion_slack: float = 1e-9
    """Interior slack (metres) separating "touching" from "overlapping" in the
    extrusion checker (regularised semantics: touching is not a collision). A
    violation needs a float64-verified point strictly inside both shapes; a
    certificate needs a dual bound of at most this slack. Set well above the LP
    solver tolerance (HiGHS ~1e-9 relative to the scaled problem); the verdict is
    exact outside the band between the rounding pad and this slack."""

    witness_candidates: int = 9
    """Candidate times per unresolved interval at which exact static tests look
    for a violation witness (endpoints + 7 interior). More only costs time."""

    max_frontier: int = 1024
    """Cap on the toleranced checker's frontier: at most this many sub-intervals of one
    pair are split at one subdivision level (earliest first); the pair's later
    sub-intervals that would be split end as unresolved intervals (-> witness search,
    else "uncertain"; never "certified"). Without it a colliding or grazing pair at a
    small epsilon doubles its frontier per level (one pair grew a process to 3.7 GB at
    epsilon 1e-5). Measured on the bench's colliding box pair at epsilon 1e-5: peak RSS
    3.4 GB (no cap, 20 s budget exhausted) vs 0.89 GB (4096) vs 0.38 GB (1024, 2.7 s,
    violation confirmed). 1024 = 10 full levels of one window. 0 = no cap (memory is then
    bounded only by ``max_depth`` and the budget)."""

    def __post_init__(self) -> None:
        """Validate every field (a negative pad or a NaN would certify collisions).

        Raises:
            InvalidInputError: naming the field: floats must be finite real numbers
                (``quat_norm_tol`` in (0, 1e-2], pads and ``extrusion_slack`` >= 0); ints
                must be integers (not bool) with ``max_depth`` >= 1, ``facets`` >= 3,
                ``witness_candidates`` >= 1 and ``max_frontier`` >= 0 (0 = no cap).
        """
        from monitor.errors import InvalidInputError  # leaf module: imported lazily

        for name in ("quat_norm_tol", "rel_pad", "abs_pad", "scale_pad", "extrusion_slack"):
            v = getattr(self, name)
            if not _is_real(v) or not math.isfinite(float(v)):
                raise InvalidInputError(f"Tolerances.{name} must be a finite real number, got {v!r}")
            v = float(v)
            if v < 0:
                raise InvalidInputError(f"Tolerances.{name} must be >= 0, got {v!r}")
            object.__setattr__(self, name, v)
        if not 0.0 < self.quat_norm_tol <= 1e-2:
            raise InvalidInputError(f"Tolerances.quat_norm_tol must be in (0, 1e-2] (a quaternion this far "
                                    f"from unit norm is a mistake, not rounding), got {self.quat_norm_tol!r}")
        for name, lo in (("max_depth", 1), ("facets", 3), ("witness_candidates", 1), ("max_frontier", 0)):
            v = getattr(self, name)
            if isinstance(v, bool) or not _is_integer(v):
                raise InvalidInputError(f"Tolerances.{name} must be an integer, got {v!r}")
            if int(v) < lo:
                raise InvalidInputError(f"Tolerances.{name} must be >= {lo}, got {v!r}")
            object.__setattr__(self, name, int(v))

    def pad(self, magnitude: float) -> float:
        """Rounding pad for a quantity of the given magnitude (metres)."""
        return self.rel_pad * abs(magnitude) + self.abs_pad


DEFAULT = Tolerances()

__all__ = ["Tolerances", "DEFAULT"]
