"""Red team 18: end to end, a `certified` step's applied motion is clear (docs/notes/redteam-18.md).

The audit (``docs/notes/redteam-18/audit.py``) re-simulates every gated step from the state before it
with the control the env received, checks the replay against the env's state bit for bit, and audits
the continuous joint-space path through the substeps (and the certified braking tail) of every
monitored pair with its own oracle (``oracle18.py``: closed forms / nnls distances with verified
witnesses, a Lipschitz bound between samples; no code shared with ``monitor``). The positive control:
the oracle must also confirm the proposals the gate rejected as violations (tunnel: the ball driven
into the walls). Slow (~5-10 s warm): the fast suite keeps its budget.
"""

from __future__ import annotations

import sys
from pathlib import Path

import gymnasium as gym
import mujoco
import pytest

AUDIT_DIR = Path(__file__).resolve().parents[1] / "docs" / "notes" / "redteam-18"


@pytest.fixture(scope="module")
def audit():
    sys.path.insert(0, str(AUDIT_DIR))
    try:
        import audit as mod  # docs/notes/redteam-18/audit.py
    finally:
        sys.path.remove(str(AUDIT_DIR))
    return mod


@pytest.mark.slow
def test_tunnel_gate_step_certified_motions_are_clear_and_violations_confirmed(audit):
    cnt = audit.run_plain("tunnel", "tunnel", {"random": 30, "hold": 30, "bang": 10}, 6, 1,
                          lambda m, d: mujoco.mj_resetDataKeyframe(m, d, 0), margin=0.001)
    assert cnt.c["win_audited"] > 0 and cnt.c["tail_audited"] > 0
    assert cnt.c["violation_proposals"] > 0  # the schedule drives the ball into the walls
    assert cnt.c["violation_confirmed_by_oracle"] == cnt.c["violation_proposals"]
    assert cnt.bad() == 0, cnt.details
    assert cnt.c["nan_refused"] == 2


@pytest.mark.slow
def test_pusher_and_wrapped_ant_certified_motions_are_clear(audit):
    sched = {"random": 15, "hold": 15, "bang": 6}
    pusher = audit.run_gym("Pusher-v5", lambda: audit.SafetyGate(gym.make("Pusher-v5")), sched, 0)
    ant = audit.run_gym(
        "Ant-v5 wrapped",
        lambda: audit.SafetyGate(gym.wrappers.NormalizeObservation(gym.wrappers.ClipAction(
            gym.wrappers.RescaleAction(gym.make("Ant-v5"), -0.5, 0.5)))), sched, 3, over=3.0)
    for cnt in (pusher, ant):
        assert cnt.c["win_audited"] > 0
        assert cnt.bad() == 0, (cnt.name, cnt.details)
        assert cnt.c["nan_refused"] == 2


@pytest.mark.slow
def test_the_audit_catches_a_gate_that_calls_everything_certified(audit, monkeypatch):
    """The audit can fail: relabel every certificate `certified` and it reports the wall hits."""
    import dataclasses

    from monitor.certify.types import Verdict
    from monitor.gate import Gate

    orig_certify, orig_init = Gate._certify, Gate.__init__

    def always_certified(self, plan):
        cert, us = orig_certify(self, plan)
        return dataclasses.replace(cert, verdict=Verdict.CERTIFIED), us

    def init(self, *a, **k):
        orig_init(self, *a, **k)
        self._joint_tail = False  # every window through _certify

    monkeypatch.setattr(Gate, "_certify", always_certified)
    monkeypatch.setattr(Gate, "__init__", init)
    cnt = audit.run_plain("tunnel planted", "tunnel", {"random": 30, "hold": 30, "bang": 10}, 6, 1,
                          lambda m, d: mujoco.mj_resetDataKeyframe(m, d, 0), margin=0.001)
    hits = [d for d in cnt.details if d["kind"] == "finding"]
    assert cnt.c["finding"] > 0 and hits
    # cross-check of the oracle's verified witness with MuJoCo's own distance (sphere-box here)
    assert all(d["mj_geomDistance"] < d["threshold"] for d in hits)
