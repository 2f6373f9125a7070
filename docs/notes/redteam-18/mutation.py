"""Mutation check of the audit: a gate that calls every window `certified` must produce findings.

Patches ``monitor.Gate._certify`` to relabel every certificate `certified` (and turns off the joint
window + tail call so every window goes through it), then runs the tunnel workload of ``audit.py``
(the ball driven into the walls). The audit must report findings; exit 0 when it does.

    PYTHONPATH=. python docs/notes/redteam-18/mutation.py
"""

from __future__ import annotations

import dataclasses
import sys
from pathlib import Path

import mujoco

sys.path.insert(0, str(Path(__file__).resolve().parent))
import audit  # noqa: E402

import monitor  # noqa: E402
from monitor.gate import Gate  # noqa: E402

_orig = Gate._certify


def _always_certified(self, plan):
    """The real certificate, relabelled `certified` (the planted bug)."""
    cert, us = _orig(self, plan)
    return dataclasses.replace(cert, verdict=monitor.Verdict.CERTIFIED), us


def main() -> int:
    """Run the tunnel workload with the planted bug; exit 0 iff the audit reports findings."""
    Gate._certify = _always_certified
    orig_init = Gate.__init__

    def init(self, *a, **k):
        orig_init(self, *a, **k)
        self._joint_tail = False

    Gate.__init__ = init
    cnt = audit.run_plain("tunnel (planted: always certified)", "tunnel",
                          {"random": 30, "hold": 30, "bang": 10}, 6, 1,
                          lambda m, d: mujoco.mj_resetDataKeyframe(m, d, 0), margin=0.001)
    print(cnt.line())
    for d in cnt.details[:3]:
        print("   ", d)
    return 0 if cnt.c["finding"] > 0 else 1


if __name__ == "__main__":
    sys.exit(main())
