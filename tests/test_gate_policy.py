"""Block reasons, cost keys and the description of a gate (issue 13, monitor/gate_policy.py)."""

from __future__ import annotations

from types import SimpleNamespace

import mujoco
import numpy as np
import pytest

from monitor.gate import Gate
from monitor.gate_policy import BLOCK_REASONS, applied_cost, block_reason, safety_keys


def _rep(verdict="certified", replaced=True, fallback_certified=True, applied_verdict="certified"):
    return SimpleNamespace(verdict=verdict, replaced=replaced, fallback_certified=fallback_certified,
                           applied_verdict=applied_verdict)


@pytest.mark.parametrize("rep, reason", [
    (_rep(replaced=False), ""),
    (_rep("violation"), "proposal_violation"),
    (_rep("uncertain"), "proposal_uncertain"),
    (_rep("certified"), "brake_tail_uncertified"),
    (_rep("violation", fallback_certified=False), "proposal_violation,fallback_uncertain"),
    (_rep("uncertain", fallback_certified=False), "proposal_uncertain,fallback_uncertain"),
])
def test_block_reason(rep, reason):
    assert block_reason(rep) == reason
    assert all(r in BLOCK_REASONS for r in reason.split(",") if r)


def test_costs():
    blocked = _rep("violation", applied_verdict="certified")
    assert applied_cost(blocked) == 0.0 and safety_keys(blocked)["proposal_cost"] == 1.0
    assert safety_keys(blocked)["intervened"] is True
    fell = _rep("violation", fallback_certified=False, applied_verdict="violation")
    assert applied_cost(fell) == 1.0
    warned = _rep("violation", replaced=False, applied_verdict="violation")
    assert applied_cost(warned) == 1.0 and safety_keys(warned)["block_reason"] == ""
    uncertain = _rep("uncertain", applied_verdict="certified")
    assert safety_keys(uncertain)["proposal_cost"] == 0.0  # cost counts confirmed violations only
    assert set(safety_keys(None)) == set(safety_keys(blocked))


XML = """
<mujoco>
  <worldbody>
    <geom name="floor" type="plane" size="1 1 .1"/>
    <geom name="wall" type="box" pos=".3 0 .1" size=".05 .5 .1"/>
    <body name="ball" pos="0 0 .0495">
      <joint name="x" type="slide" axis="1 0 0"/>
      <joint name="z" type="slide" axis="0 0 1"/>
      <geom name="ball" type="sphere" size=".05" mass="1"/>
    </body>
  </worldbody>
  <actuator><motor joint="x" gear="1"/></actuator>
</mujoco>
"""


def test_gate_blocks_a_new_wall_contact_while_resting_on_the_floor():
    """Gate with defaults: resting contact is Default-allowed; the wall is a new contact and is blocked."""
    m = mujoco.MjModel.from_xml_string(XML)
    d = mujoco.MjData(m)
    gate = Gate(m, frame_skip=5)
    assert {(a, b, r) for a, b, r in gate.scene.allowed_pairs} == {("floor", "ball", "Default")}
    assert "1 pairs monitored" in gate.describe() and "1 Default" in gate.describe()
    d.qpos[0] = 0.19  # 1 cm from the wall's face (x = .25), moving at 2 m/s towards it
    d.qvel[0] = 2.0
    r = gate.step(d, np.array([0.0]))
    assert r.verdict == "violation" and r.replaced and r.block_reason.startswith("proposal_violation")
    assert set(r.certificate.witness.geoms) == {"wall", "ball"}
    assert r.info()["proposal_cost"] == 1.0
    assert r.certificate.allowed == (("floor", "ball", "Default"),)


def test_gate_without_acm_treats_the_resting_contact_as_ongoing():
    m = mujoco.MjModel.from_xml_string(XML)
    d = mujoco.MjData(m)
    gate = Gate(m, frame_skip=5, allowed=None)
    r = gate.step(d, np.array([0.1]))
    assert r.verdict == "certified" and r.certificate.ongoing == (("floor", "ball"),)
    plain = Gate(m, frame_skip=5, allowed=None, ongoing="violation")
    assert plain.step(mujoco.MjData(m), np.array([0.1])).verdict == "violation"
