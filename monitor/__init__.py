"""monitor: certify that a MuJoCo motion window is collision-free before it runs.

Public API (imported lazily so that ``import monitor`` stays cheap and the
algorithms never pull in gymnasium or mcap):

* Scene and trajectories: :class:`Scene`, :class:`Plan`, :class:`BodyMotion` (lerp/slerp or screw),
  :class:`BezierMotion` / :class:`RigidBezier` (rational Bézier motions)
* Certification: :func:`certify`, :class:`Certificate`, :class:`PairResult`, :class:`Witness`;
  :class:`Verdict` (``CERTIFIED | VIOLATION | UNCERTAIN``, the type of ``Certificate.verdict``
  and ``PairResult.verdict``) and :class:`Method` (``AUTO | TOLERANCED | EXTRUSION``, for
  ``certify(method=...)``; plain strings are accepted too). Both are ``enum.StrEnum``: each
  member equals, prints and serialises as its string (``cert.verdict == "certified"``).
* Gating: :class:`Gate` (plain MuJoCo), :class:`SafetyGate` (gymnasium wrapper)
* Logs: :class:`MonitorLog` (``monitor.log``)
* Errors and tolerances: :mod:`monitor.errors`, :class:`Tolerances`
"""

from __future__ import annotations

import importlib
from typing import Any

__version__ = "0.1.0"

_LAZY = {
    "Scene": "monitor.scene",
    "GeomInfo": "monitor.scene",
    "Plan": "monitor.motion.plan",
    "BodyMotion": "monitor.motion.bodymotion",
    "BezierMotion": "monitor.motion.bezier",
    "RigidBezier": "monitor.motion.bezier",
    "certify": "monitor.certify.engine",
    "Certificate": "monitor.certify.certificate",
    "PairResult": "monitor.certify.certificate",
    "Witness": "monitor.certify.certificate",
    "Verdict": "monitor.certify.types",
    "Method": "monitor.certify.types",
    "CertifyRequest": "monitor.certify.request",
    "BudgetLimits": "monitor.certify.request",
    "Gate": "monitor.gate",
    "StepReport": "monitor.gate",
    "SafetyGate": "monitor.gym_gate",
    "MonitorLog": "monitor.log.writer",
    "rollouts": "monitor.rollouts",
    "RolloutSummary": "monitor.rollouts",
    "RandomPolicy": "monitor.rollouts",
    "Tolerances": "monitor.tolerances",
    "MonitorError": "monitor.errors",
    "InvalidInputError": "monitor.errors",
    "ModelMismatchError": "monitor.errors",
    "UnsupportedGeometryError": "monitor.errors",
    "LogFormatError": "monitor.errors",
}

__all__ = sorted(_LAZY) + ["__version__"]


def __getattr__(name: str) -> Any:
    mod = _LAZY.get(name)
    if mod is None:
        raise AttributeError(f"module 'monitor' has no attribute {name!r}")
    if name == "certify":
        # the callable subpackage (forwards to engine.certify), never the bare function:
        # binding the function here would shadow the package, and a later
        # ``import monitor.certify.engine as e`` would then fail
        value = importlib.import_module("monitor.certify")
    else:
        value = getattr(importlib.import_module(mod), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return __all__
