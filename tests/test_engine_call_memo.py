"""The engine's per-scene call memo (``engine._call_memo`` / ``_remember_call``, issue 12).

A second ``certify`` with the very scene, plan and request objects of the previous call reuses
that call's validated inputs (window, selection, packs, kernel flags). It must never outlive
what they were derived from. Oracle: a fresh ``Scene`` (and ``Plan``) built on the model as it
is, which no memo has seen; and the Python pipeline for the memo's replaceable functions.
"""

from __future__ import annotations

import mujoco
import numpy as np

import monitor
from monitor.certify import engine
from monitor.certify.request import CertifyRequest

WALL_XML = """<mujoco><worldbody>
 <geom name="wall" type="box" size="0.05 0.5 0.5" pos="0.5 0 0"/>
 <body name="b"><joint name="s" type="slide" axis="0 1 0"/>
  <geom name="ball" type="sphere" size="0.1" pos="0.3 0 0"/></body>
</worldbody></mujoco>"""


def _summary(cert) -> dict:
    d = cert.to_dict()
    d["stats"].pop("wall_seconds")
    return d


def _wall():
    m = mujoco.MjModel.from_xml_string(WALL_XML)
    return m, monitor.Scene.from_model(m, pairs="all")


def _slide_motion() -> monitor.BodyMotion:
    """Body 1 slides 0.4 m along y in 0.1 s (the ball's nearest face stays 0.05 m from the wall)."""
    pos = np.zeros((2, 2, 3))
    pos[:, 1, 1] = (-0.2, 0.2)
    quat = np.zeros((2, 2, 4))
    quat[..., 0] = 1.0
    return monitor.BodyMotion([0.0, 0.1], pos, quat)


def test_reused_plan_and_request_follow_an_in_place_edit():
    """Same Plan and request object before and after the ball grows into the wall."""
    m, scene = _wall()
    plan = monitor.Plan([0, 0.1], [[-0.2], [0.2]], m)
    req = CertifyRequest(epsilon=1e-3, method="toleranced")
    first = monitor.certify(scene, plan, request=req)
    assert scene._hot["call"][0] is plan                     # the memo holds this call
    again = monitor.certify(scene, plan, request=req)        # a memo hit
    assert first.verdict == "certified" and _summary(again) == _summary(first)
    m.geom_size[m.geom("ball").id][0] = 0.2
    edited = monitor.certify(scene, plan, request=req)
    assert edited.verdict == "violation"
    fresh = monitor.certify(monitor.Scene.from_model(m, pairs="all"),
                            monitor.Plan([0, 0.1], [[-0.2], [0.2]], m), request=req)
    assert _summary(edited) == _summary(fresh)


def test_reused_plan_is_refreshed_after_a_body_pos_edit():
    """A body_pos edit makes the stored Plan stale: it is rebuilt, as without the memo."""
    m, scene = _wall()
    plan = monitor.Plan([0, 0.1], [[-0.2], [0.2]], m)
    req = CertifyRequest(epsilon=1e-3)
    assert monitor.certify(scene, plan, request=req).verdict == "certified"
    m.body_pos[m.body("b").id][0] = 0.15                     # ball face at 0.55 > wall face 0.45
    edited = monitor.certify(scene, plan, request=req)
    fresh = monitor.certify(monitor.Scene.from_model(m, pairs="all"),
                            monitor.Plan([0, 0.1], [[-0.2], [0.2]], m), request=req)
    assert edited.verdict == "violation"
    assert _summary(edited) == _summary(fresh)


def test_reused_body_motion_follows_an_in_place_edit():
    m, scene = _wall()
    motion = _slide_motion()
    for _ in range(2):
        cert = monitor.certify(scene, motion, epsilon=1e-3)
        assert cert.verdict == "certified" and cert.clearance > 0.0
    m.geom_size[m.geom("ball").id][0] = 0.2
    edited = monitor.certify(scene, motion, epsilon=1e-3)
    assert edited.verdict == "violation"
    assert _summary(edited) == _summary(monitor.certify(monitor.Scene.from_model(m, pairs="all"),
                                                        _slide_motion(), epsilon=1e-3))


def test_memo_honours_a_replaced_fast_path(monkeypatch):
    """After a memoised call, switching the compiled path off sends the same call to the Python stages."""
    m, scene = _wall()
    motion = _slide_motion()
    compiled = monitor.certify(scene, motion, epsilon=1e-3, method="toleranced")
    ran = []
    real = engine._certify
    monkeypatch.setattr(engine, "_fast_inputs", lambda scene, plan: None)
    monkeypatch.setattr(engine, "_certify", lambda *a: ran.append(1) or real(*a))
    python = monitor.certify(scene, motion, epsilon=1e-3, method="toleranced")
    assert ran == [1]
    assert python.verdict == compiled.verdict == "certified"


def test_plan_of_another_equal_model_is_not_memoised():
    """Such a plan's model is hashed on every call (it may be edited in place): nothing is kept."""
    m, scene = _wall()
    other = mujoco.MjModel.from_xml_string(WALL_XML)
    plan = monitor.Plan([0, 0.1], [[-0.2], [0.2]], other)
    monitor.certify(scene, plan)
    assert "call" not in scene._hot
    other.geom_size[other.geom("ball").id][0] = 0.2          # now a different model
    try:
        monitor.certify(scene, plan)
    except monitor.errors.ModelMismatchError:
        pass
    else:
        raise AssertionError("a plan of an edited other model was certified")


def test_request_memo_follows_the_budget_limits():
    """The same keyword objects with a Budget: the request (and its limits) follow the Budget of each call."""
    from monitor.certify.common import Budget

    m, scene = _wall()
    motion = _slide_motion()
    eps = 1e-3
    seen = []
    for seconds, tests in ((1.0, None), (1.0, None), (2.0, None), (2.0, 10**6), (1.0, None)):
        budget = Budget(seconds=seconds, tests=tests)
        cert = monitor.certify(scene, motion, margin=0.0, epsilon=eps, budget=budget)
        seen.append((cert.request.budget.seconds, cert.request.budget.tests))
    assert seen == [(1.0, None), (1.0, None), (2.0, None), (2.0, 10**6), (1.0, None)]
    default = monitor.certify(scene, motion, margin=0.0, epsilon=eps)
    assert default.request.budget.seconds == engine.DEFAULT_BUDGET_SECONDS


def test_waypoints_cannot_be_made_writable_after_a_certify():
    """The memos trust a trajectory's waypoints: the arrays a Plan / BodyMotion / BezierMotion
    exposes refuse ``setflags(write=True)``, so no edit can follow a cached call."""
    import pytest

    m, scene = _wall()
    plan = monitor.Plan([0, 0.1], [[-0.2], [0.2]], m)
    monitor.certify(scene, plan)
    motion = _slide_motion()
    for arr in (plan.times, plan.qpos, motion.times, motion.pos, motion.quat):
        with pytest.raises(ValueError):
            arr.setflags(write=True)
    # a trusted (gate-made) Plan whose rows are views of a caller's writable buffer: copied
    rows = np.array([[0.0, -0.2], [0.1, 0.2]])
    trusted = monitor.Plan._trusted(rows[:, 0], rows[:, 1:], m, mocap_pos=np.zeros((0, 3)),
                                    mocap_quat=np.zeros((0, 4)))
    rows[1, 1] = 5.0
    assert trusted.qpos[1, 0] == 0.2
    with pytest.raises(ValueError):
        trusted.qpos.setflags(write=True)
