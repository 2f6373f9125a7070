"""Issue 11: every certify call has a bounded time, and an exhausted budget never certifies.

* ``budget=None`` means :data:`monitor.certify.common.DEFAULT_BUDGET_SECONDS`.
* Budget arguments are validated (``{"seconds": "1"}`` is an InvalidInputError naming it).
* The budget is polled inside every stage: a deterministic budget that runs out after
  its k-th poll, swept over k, must never turn the arm's collision into "certified"
  (nor a clear motion into "violation").
* Timing bounds (the 1e8-rad plan, a long chain) are slow-marked: wall time is not a
  pass/fail criterion of the fast suite.
"""

from __future__ import annotations

import time
import warnings
from pathlib import Path

import mujoco
import numpy as np
import pytest

import monitor
import monitor.certify.engine as engine
from monitor.certify.common import DEFAULT_BUDGET_SECONDS, Budget
from monitor.errors import InvalidInputError

ARM = Path(__file__).resolve().parents[1] / "models" / "arm" / "scene.xml"


@pytest.fixture(scope="module")
def arm():
    m = mujoco.MjModel.from_xml_path(str(ARM))
    return m, monitor.Scene.from_model(m)


def _yaw(m, d: float, t1: float = 0.5):
    q1 = m.qpos0.copy()
    q1[0] += d
    return monitor.Plan([0.0, t1], [m.qpos0, q1], m)


class PollBudget(Budget):
    """Deterministic budget: exhausted from its ``limit``-th poll of ``exhausted`` on."""

    def __init__(self, limit: int):
        super().__init__()
        self.limit = limit
        self.polls = 0

    @property
    def exhausted(self) -> bool:
        self.polls += 1
        return self.polls > self.limit


# ----------------------------------------------------------------------------- validation

@pytest.mark.parametrize(("kwargs", "field"), [
    ({"seconds": "1"}, "seconds"), ({"seconds": -1.0}, "seconds"), ({"seconds": float("nan")}, "seconds"),
    ({"seconds": float("inf")}, "seconds"), ({"seconds": True}, "seconds"),
    ({"tests": 1.5}, "tests"), ({"tests": -1}, "tests"), ({"tests": "10"}, "tests"),
    ({"tests": False}, "tests"),
])
def test_budget_fields_are_validated(kwargs, field):
    with pytest.raises(InvalidInputError, match=field):
        Budget(**kwargs)


@pytest.mark.parametrize(("budget", "field"), [
    ({"seconds": "1"}, "seconds"), ({"tests": 2.5}, "tests"), ({"second": 1.0}, "second"), (3, "budget"),
])
def test_certify_rejects_bad_budget_arguments(arm, budget, field):
    m, scene = arm
    with pytest.raises(InvalidInputError, match=field):
        monitor.certify(scene, _yaw(m, 0.3), budget=budget)


def test_good_budget_forms_are_accepted(arm):
    m, scene = arm
    for budget in (None, Budget(seconds=30), {"seconds": 30}, {"tests": 10**9},
                   Budget(seconds=np.float32(30.0))):
        assert monitor.certify(scene, _yaw(m, 0.3), budget=budget).verdict == "certified"


# ----------------------------------------------------------------------------- default budget

def test_default_budget_applies_when_none_is_given(arm, monkeypatch):
    """budget=None is not unlimited: with the default patched to 0 s nothing can finish."""
    m, scene = arm
    assert DEFAULT_BUDGET_SECONDS == engine.DEFAULT_BUDGET_SECONDS > 0
    monkeypatch.setattr(engine, "DEFAULT_BUDGET_SECONDS", 0.0)
    cert = monitor.certify(scene, _yaw(m, 0.3))
    assert cert.verdict == "uncertain"
    assert cert.stats["budget_exhausted"] is True
    assert any(p.method == "budget" for p in cert.pairs)


def test_huge_joint_jump_ends_uncertain_without_overflow(arm):
    """Issue reproduction (shortened): a 1e8-rad jump; the old code ran > 400 s with NaN warnings."""
    m, scene = arm
    plan = _yaw(m, 1e8, t1=0.1)
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        cert = monitor.certify(scene, plan, budget=PollBudget(40))
    assert cert.verdict in ("uncertain", "violation")


# ----------------------------------------------------------------------------- every stage

@pytest.mark.parametrize(("yaw", "min_polls"), [(1.0, 1), (3.0, 5)])
def test_exhaustion_at_every_poll_never_certifies_the_collision(arm, yaw, min_polls):
    """Sweep the poll at which the budget runs out over every poll the call makes.

    (yaw 3.0: the whole-shape searches spend several times ``kernels.CALL_TESTS`` tests, so the
    compiled stage stops and resumes between polls.)
    """
    m, scene = arm
    plan = _yaw(m, yaw)  # link3 yaws through post_a
    full = PollBudget(10**9)
    assert monitor.certify(scene, plan, budget=full).verdict == "violation"
    n = full.polls
    assert n > min_polls
    seen = set()
    for k in range(n + 2):
        cert = monitor.certify(scene, _yaw(m, yaw), budget=PollBudget(k))
        assert cert.verdict != "certified", k
        seen.add(cert.verdict)
        assert len(cert.pairs) == len(scene.candidate_pairs)
    assert seen == {"uncertain", "violation"}


def test_exhaustion_at_every_poll_never_reports_a_false_violation(arm):
    m, scene = arm
    full = PollBudget(10**9)
    assert monitor.certify(scene, _yaw(m, 0.3), budget=full).verdict == "certified"
    seen = set()
    for k in range(full.polls + 2):
        cert = monitor.certify(scene, _yaw(m, 0.3), budget=PollBudget(k))
        assert cert.verdict in ("certified", "uncertain"), k
        seen.add(cert.verdict)
        if cert.verdict == "uncertain":
            assert cert.clearance == float("-inf")
    assert seen == {"certified", "uncertain"}


def test_motion_bounds_poll_the_active_budget(arm):
    """The stage the old code never checked: Plan.motion_bounds inside certify."""
    from monitor.certify.common import BudgetExhausted, active_budget

    m, _ = arm
    plan = _yaw(m, 0.3)
    with active_budget(Budget(seconds=0.0)), pytest.raises(BudgetExhausted):
        plan.motion_bounds(np.array([0.0]), np.array([0.5]))
    plan.motion_bounds(np.array([0.0]), np.array([0.5]))  # no active budget: no limit


# ----------------------------------------------------------------------------- wall-time bounds

def _chain(n: int):
    spec = mujoco.MjSpec()
    spec.worldbody.add_geom(name="post", type=mujoco.mjtGeom.mjGEOM_BOX, size=[0.1, 0.1, 0.1], pos=[0, 1, 0])
    parent = spec.worldbody
    for _ in range(n):
        parent = parent.add_body(pos=[0.05, 0, 0])
        parent.add_joint(type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0, 0, 1])
        parent.add_geom(type=mujoco.mjtGeom.mjGEOM_CAPSULE, fromto=[0, 0, 0, 0.05, 0, 0], size=[0.01, 0, 0])
    return spec.compile()


@pytest.mark.slow
@pytest.mark.parametrize("case", ["jump_1e8", "chain_300"])
def test_wall_time_stays_near_the_budget(arm, case):
    """Issue goal: <= 1.5 x budget + 10 ms (asserted with slack for a loaded machine: 2 x + 0.5 s)."""
    m, scene = arm
    monitor.certify(scene, _yaw(m, 0.3))  # warm-up: imports and numba caches
    if case == "jump_1e8":
        plan, sc, budget = _yaw(m, 1e8, t1=0.1), scene, 1.0
    else:
        mc = _chain(300)
        sc = monitor.Scene.from_model(mc)
        plan = monitor.Plan([0, 0.1], [np.zeros(mc.nq), np.full(mc.nq, 0.01)], mc)
        budget = 1.0
    t = time.perf_counter()
    cert = monitor.certify(sc, plan, budget={"seconds": budget})
    wall = time.perf_counter() - t
    assert cert.verdict != "certified" or not cert.stats["budget_exhausted"]
    assert wall <= 2.0 * budget + 0.5, wall


def test_float_seconds_are_validated_on_the_fast_path_too():
    """Budget(seconds=<float>) takes a shortcut for finite floats >= 0: the rest still raise."""
    import math

    from monitor.certify.common import Budget
    from monitor.errors import InvalidInputError
    for bad in (float("nan"), -1.0, -1e-300, math.inf, -math.inf):
        with pytest.raises(InvalidInputError, match="seconds"):
            Budget(seconds=bad)
    with pytest.raises(InvalidInputError, match="tests"):
        Budget(seconds=1.0, tests=-1)
    assert Budget(seconds=0.0).seconds == 0.0 and Budget(seconds=2.5, tests=3).tests == 3


def test_active_budget_nests_and_is_restored_after_an_exception():
    from monitor.certify import common
    from monitor.certify.common import Budget, active_budget
    outer, inner = Budget(seconds=1.0), Budget(tests=0)
    assert getattr(common._ACTIVE, "budget", None) is None
    with active_budget(outer):
        assert common._ACTIVE.budget is outer
        with pytest.raises(common.BudgetExhausted):
            with active_budget(inner):
                common.check_active_budget()
        assert common._ACTIVE.budget is outer
    assert getattr(common._ACTIVE, "budget", None) is None
