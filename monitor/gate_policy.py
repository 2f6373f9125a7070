"""What a gate monitors, why it blocked, and what a step cost (issue 13).

Helpers used by :class:`monitor.Gate` and :class:`monitor.SafetyGate` through
one-line hooks, so that the gating logic in ``gate.py`` stays small.

``info["safety"]`` keys added here (``SAFETY_INFO_VERSION`` = 2):

* ``version`` (int): version of the ``info["safety"]`` layout (2 adds the keys below).
* ``proposal_cost`` (float): 1.0 when the *proposed* action's window has a confirmed
  violation on a monitored pair, else 0.0 (also when the proposal was blocked).
* ``intervened`` (bool): the proposed action was replaced.
* ``block_reason`` (str): ``""`` when not replaced; otherwise why, comma-joined:
  first one of ``"proposal_violation"``, ``"proposal_uncertain"``,
  ``"brake_tail_uncertified"`` (the proposal's own window certified, but the braking
  tail after it did not), then ``"fallback_uncertain"`` when the replacement's own
  window did not certify either.

``info["cost"]`` (safety-gymnasium's convention) is the cost of the transition that
happened: 1.0 when the *applied* window has a confirmed violation on a monitored
pair, else 0.0 (:func:`applied_cost`).

This module imports mujoco and monitor only (no gymnasium).
"""

from __future__ import annotations

import logging
import warnings
from collections import Counter
from typing import Any

from monitor.certify.types import Verdict

_LOG = logging.getLogger("monitor.gate")

SAFETY_INFO_VERSION = 2
"""Version of the ``info["safety"]`` layout (see module docstring)."""
BLOCK_REASONS = ("proposal_violation", "proposal_uncertain", "brake_tail_uncertified", "fallback_uncertain")


def describe_gate(gate: Any) -> str:
    """One line: pairs monitored, allowed pairs per reason, the ongoing-contact rule."""
    scene = gate.scene
    n = len(scene.pair_ids)
    counts = Counter(r for _a, _b, r in scene.allowed_pairs)
    allowed = ", ".join(f"{counts[r]} {r}" for r in sorted(counts)) or "none"
    mode = gate.pairs if isinstance(gate.pairs, str) else "list"
    rule = (f"ongoing contacts may deepen to {gate.penetration_tol:g} m" if gate.ongoing == "deepen"
            else "contacts at window start are violations")
    hz = "" if gate.hazards is None else f", hazards={gate.hazards!r}"
    return (f"monitor.Gate: {n} pairs monitored (pairs={mode!r}{hz}), allowed and not checked: {allowed}; "
            f"margin {gate.margin:g} m; {rule}")


def announce(gate: Any) -> None:
    """Log what the gate monitors (INFO) and warn once if it monitors nothing."""
    line = describe_gate(gate)
    _LOG.info("%s", line)
    if not gate.scene.candidate_pairs and not getattr(gate, "_warned_empty", False):
        gate._warned_empty = True
        warnings.warn(f"{line}: the gate checks NOTHING (no candidate pair after contype/conaffinity, "
                      "exclusions and the allowed-contact matrix); pass pairs='all', hazards=... or "
                      "allowed=None to monitor something", UserWarning, stacklevel=4)


def block_reason(report: Any) -> str:
    """Why a report's proposal was replaced (``""`` when it was not); see module docstring."""
    if not report.replaced:
        return ""
    if report.verdict == Verdict.VIOLATION:
        why = ["proposal_violation"]
    elif report.verdict != Verdict.CERTIFIED:
        why = ["proposal_uncertain"]
    else:
        why = ["brake_tail_uncertified"]
    if not report.fallback_certified:
        why.append("fallback_uncertain")
    return ",".join(why)


def applied_cost(report: Any) -> float:
    """1.0 when the applied window has a confirmed violation, else 0.0."""
    return 1.0 if report.applied_verdict == Verdict.VIOLATION else 0.0


def safety_keys(report: Any | None) -> dict[str, Any]:
    """The version-2 keys of ``info["safety"]`` (blank values for ``report=None``, e.g. reset)."""
    if report is None:
        return {"version": SAFETY_INFO_VERSION, "proposal_cost": 0.0, "intervened": False, "block_reason": ""}
    return {"version": SAFETY_INFO_VERSION,
            "proposal_cost": 1.0 if report.verdict == Verdict.VIOLATION else 0.0,
            "intervened": bool(report.replaced), "block_reason": block_reason(report)}


__all__ = ["SAFETY_INFO_VERSION", "BLOCK_REASONS", "describe_gate", "announce", "block_reason",
           "applied_cost", "safety_keys"]
