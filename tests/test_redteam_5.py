"""Red team 5: ``certified`` for a motion that breaks what the certificate states (rt5).

Every test here failed on the base commit ff8b94e unless its docstring says it is a guard
(see docs/notes/redteam-5.md). Oracles are closed forms independent of the checkers: a sphere
of radius r above the horizontal plane z = 0 is at distance ``z - r``; on a straight (linear)
motion that distance is linear in time, so its least value over the motion is the smaller of
its two ends.
"""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from monitor.certify.engine import certify
from monitor.motion.plan import Plan
from monitor.scene import Scene

BALL_R = 0.1
MARGIN, TOL = 0.05, 0.005
START_GAP = 0.03  # inside the margin, apart: an ongoing pair that may close by at most TOL

# The floor is a world geom: it comes first in its pair (the usual order: world geoms have the
# smallest ids), so the ongoing rule's "A" is the half-space.
_FLOOR_XML = f"""<mujoco><worldbody><geom name="floor" type="plane" size="5 5 0.1"/>
<body name="ball" pos="0 0 0.5"><freejoint/><geom name="ball" type="sphere" size="{BALL_R}"/></body>
</worldbody></mujoco>"""


@pytest.fixture(scope="module")
def floor():
    model = mujoco.MjModel.from_xml_string(_FLOOR_XML)
    return model, Scene.from_model(model)


def _drop(model, gap0: float, gap1: float) -> Plan:
    """The ball straight down from ``gap0`` to ``gap1`` above the floor (m) in 0.1 s."""
    q0 = np.array([0.0, 0.0, BALL_R + gap0, 1.0, 0.0, 0.0, 0.0])
    q1 = q0.copy()
    q1[2] = BALL_R + gap1
    return Plan(np.array([0.0, 0.1]), np.array([q0, q1]), model=model)


@pytest.mark.parametrize("method", ["auto", "extrusion", "toleranced"])
@pytest.mark.parametrize("gap1", [0.02, 0.005, 1e-4])
def test_ongoing_pair_within_margin_closing_on_a_plane_is_not_certified(floor, method, gap1):
    """ongoing="deepen", a ball 0.03 m above a floor plane (margin 0.05: ongoing, apart) moving
    straight down: the rule lets it close by at most penetration_tol (clearance > 0.03 - 0.005).
    On ff8b94e the rule inflated A's radius to prove that, and A is the plane, whose solid has no
    radius: every drop that did not touch was certified, with a clearance above the true one
    (e.g. 0.0251 m claimed for a drop to 1e-4 m)."""
    model, scene = floor
    cert = certify(scene, _drop(model, START_GAP, gap1), margin=MARGIN, method=method, ongoing="deepen",
                   penetration_tol=TOL)
    true_min = min(START_GAP, gap1)  # closed form: linear in time
    assert true_min < START_GAP - TOL  # the motion closes by more than the tolerance
    assert cert.verdict != "certified", (cert.clearance, [p.note for p in cert.pairs])
    assert cert.stats.get("ongoing") == 1


@pytest.mark.parametrize("method", ["auto", "extrusion", "toleranced"])
def test_ongoing_pair_within_margin_closing_less_than_the_tolerance_is_certified(floor, method):
    """A drop by 0.0025 m (< penetration_tol) stays certified (a guard: the fix does not block what
    the rule allows), with a clearance that is a lower bound of the closed-form one (0.0275 m) and
    above 0.03 - 0.005. On ff8b94e it was certified with clearance 0.0525 m (overstated by x)."""
    model, scene = floor
    gap1 = START_GAP - 0.0025
    cert = certify(scene, _drop(model, START_GAP, gap1), margin=MARGIN, method=method, ongoing="deepen",
                   penetration_tol=TOL)
    assert cert.verdict == "certified", [p.note for p in cert.pairs]
    assert START_GAP - TOL < cert.clearance <= gap1 + 1e-12


_SLIDE_FLOOR_XML = """<mujoco><option timestep="0.002" gravity="0 0 0"/><worldbody>
<geom name="floor" type="plane" size="5 5 0.1" contype="0" conaffinity="0"/>
<body name="ball"><joint name="z" type="slide" axis="0 0 1"/>
  <geom name="ball" type="sphere" size="0.1" mass="0.1" contype="0" conaffinity="0"/></body>
</worldbody><actuator><velocity name="vz" joint="z" kv="50" ctrlrange="-5 5"/></actuator></mujoco>"""


def test_gate_does_not_run_a_step_closing_on_a_floor_by_more_than_the_tolerance():
    """The default Gate (ongoing="deepen", penetration_tol 5 mm), margin 0.05, a ball 0.03 m above
    a floor plane driven down at 1 m/s for 0.02 s. Oracle: the ball's height on the live data after
    the step (the motion that ran; monotone within the window): a certified applied motion keeps
    the gap above 0.03 - 0.005. On ff8b94e the proposal was certified and ran to 0.010 m."""
    import monitor

    model = mujoco.MjModel.from_xml_string(_SLIDE_FLOOR_XML)
    data = mujoco.MjData(model)
    data.qpos[0] = BALL_R + START_GAP
    mujoco.mj_forward(model, data)
    gate = monitor.Gate(model, margin=MARGIN, frame_skip=10, pairs=[("floor", "ball")])
    assert gate.ongoing == "deepen" and gate.penetration_tol == TOL
    checked = 0
    for _ in range(2):
        gap0 = float(data.qpos[0]) - BALL_R
        report = gate.step(data, np.array([-1.0]))
        gap1 = float(data.qpos[0]) - BALL_R
        if report.applied_verdict == "certified":
            checked += 1
            assert min(gap0, gap1) > START_GAP - TOL, (gap0, gap1, report.verdict, report.replaced)
    assert checked  # the gate certified what it ran (a blocked proposal's hold), so the oracle ran
