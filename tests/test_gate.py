"""monitor.Gate: rollout predictor, hold-position fallback, gating policies, reuse, budget."""

from __future__ import annotations

import logging
import math

import gymnasium as gym
import mujoco
import numpy as np
import pytest

import monitor.envs  # noqa: F401
from monitor._paths import scene_path
from monitor.certify.certificate import Certificate, Witness
from monitor.errors import InvalidInputError
from monitor.gate import Gate, Rollout, _make_budget, hold_ctrl


def _arm():
    m = mujoco.MjModel.from_xml_path(str(scene_path("arm")))
    return m, mujoco.MjData(m)


# ----------------------------------------------------------------------------- predictor
def test_rollout_is_bit_identical_to_env_step_and_leaves_live_data_alone():
    env = gym.make("Pusher-v5").unwrapped
    env.reset(seed=0)
    rng = np.random.default_rng(0)
    ro = Rollout(env.model)
    for _ in range(20):
        a = rng.uniform(-2, 2, size=7).astype(np.float32)
        before = (env.data.qpos.copy(), env.data.qvel.copy(), env.data.time)
        times, qpos = ro.states(env.data, a, env.frame_skip)
        assert np.array_equal(env.data.qpos, before[0]) and np.array_equal(env.data.qvel, before[1])
        assert env.data.time == before[2]
        env.step(a)
        assert np.array_equal(qpos[-1], env.data.qpos)
        assert times[-1] == env.data.time
        assert qpos.shape == (env.frame_skip + 1, env.model.nq)
        assert np.all(np.diff(times) > 0)


def test_rollout_plan_holds_mocap_pose():
    env = gym.make("monitor/Arm-v0").unwrapped
    env.reset(seed=4)
    plan = Rollout(env.model).plan(env.data, np.zeros(3), 3)
    assert np.array_equal(plan.mocap_pos, env.data.mocap_pos)
    assert plan.window == (env.data.time, env.data.time + 3 * env.model.opt.timestep)


# ----------------------------------------------------------------------------- fallback
def test_hold_ctrl_position_servos_exert_no_force_at_rest():
    m, d = _arm()
    rng = np.random.default_rng(1)
    for _ in range(10):
        lo, hi = m.jnt_range[:, 0], m.jnt_range[:, 1]
        d.qpos[:] = rng.uniform(lo, hi)
        d.qvel[:] = 0
        d.ctrl[:] = hold_ctrl(m, d)
        mujoco.mj_forward(m, d)
        np.testing.assert_allclose(d.actuator_force, 0.0, atol=1e-9)


def test_hold_ctrl_clips_to_ctrlrange_and_zero_for_other_actuators():
    m, d = _arm()
    d.qpos[:] = [3.5, 0.0, 0.0]  # beyond the yaw ctrlrange (+-2.9)
    np.testing.assert_array_equal(hold_ctrl(m, d), [2.9, 0.0, 0.0])
    t = mujoco.MjModel.from_xml_path(str(scene_path("tunnel")))  # velocity servo
    td = mujoco.MjData(t)
    td.qpos[0] = 0.2
    np.testing.assert_array_equal(hold_ctrl(t, td), [0.0])
    p = gym.make("Pusher-v5").unwrapped  # motors
    p.reset(seed=0)
    np.testing.assert_array_equal(hold_ctrl(p.model, p.data), np.zeros(7))


# ----------------------------------------------------------------------------- options
@pytest.mark.parametrize("kwargs", [dict(on_violation="stop"), dict(unsafe="never"), dict(margin=-0.1),
                                    dict(epsilon=0.0), dict(predictor="psychic"), dict(frame_skip=0),
                                    dict(budget="lots")])
def test_bad_options_raise(kwargs):
    m, _ = _arm()
    with pytest.raises(InvalidInputError):
        Gate(m, **kwargs)


def test_gate_rejects_non_model():
    with pytest.raises(InvalidInputError, match="MjModel"):
        Gate("scene.xml")


def test_budget_spec():
    from monitor.certify.common import Budget

    assert _make_budget(None) is None
    assert _make_budget(0.5).seconds == 0.5 and _make_budget(0.5).tests is None
    assert _make_budget(100).tests == 100 and _make_budget(100).seconds is None
    b = _make_budget({"tests": 5})
    assert isinstance(b, Budget) and b.tests == 5
    template = Budget(tests=3)
    template.charge(10)
    fresh = _make_budget(template)
    assert fresh.tests == 3 and not fresh.exhausted  # a fresh budget per window


# ----------------------------------------------------------------------------- gating logic (stub checker)
def _stub(gate, verdict_of):
    """Replace the certifier by ``verdict_of(plan) -> verdict`` (logic tests only)."""

    def fake(plan):
        v = verdict_of(plan)
        wit = Witness(plan.t1, ("a", "b"), np.zeros(3), -0.01) if v == "violation" else None
        cert = Certificate(v, plan.window, gate.margin, gate.epsilon, "auto", wit,
                           None if v == "certified" else plan.t0, 0.1 if v == "certified" else -np.inf)
        return cert, 7.0

    gate._certify = fake
    gate._scene = type("S", (), {"candidate_pairs": ()})()


def _unsafe_if_yaw_moves(plan):
    return "violation" if abs(plan.qpos[-1, 0] - plan.qpos[0, 0]) > 1e-4 else "certified"


@pytest.mark.parametrize("mode", ["block", "terminate", "warn"])
def test_policies(mode):
    m, d = _arm()
    gate = Gate(m, on_violation=mode, frame_skip=5)
    _stub(gate, _unsafe_if_yaw_moves)
    ref = mujoco.MjData(m)
    proposal = np.array([1.0, 0.0, 0.0])
    r = gate.step(d, proposal)
    assert r.verdict == "violation" and r.unsafe and r.stepped
    if mode == "warn":
        assert not r.replaced and np.array_equal(r.applied_ctrl, proposal)
    else:
        assert r.replaced and np.array_equal(r.applied_ctrl, hold_ctrl(m, ref))
        assert r.applied_verdict == "certified" and r.fallback_certified
    assert r.terminated == (mode == "terminate")
    # the caller's data advanced exactly as mj_step with the applied control
    ref.ctrl[:] = r.applied_ctrl
    mujoco.mj_step(m, ref, nstep=5)
    assert np.array_equal(ref.qpos, d.qpos)
    info = r.info()
    assert info["verdict"] == "violation" and info["replaced"] == (mode != "warn")
    assert info["witness_geoms"].tolist() == ["a", "b"] and info["witness_point"].shape == (3,)
    # issue 13: info["cost"] is the applied window's; the proposal's is proposal_cost
    assert r.cost == (1.0 if mode == "warn" else 0.0) and info["proposal_cost"] == 1.0
    assert info["intervened"] == (mode != "warn")
    assert info["block_reason"] == ("" if mode == "warn" else "proposal_violation")


def test_unsafe_violation_admits_uncertain():
    m, d = _arm()
    for unsafe, replaced in (("uncertain", True), ("violation", False)):
        gate = Gate(m, unsafe=unsafe)
        _stub(gate, lambda plan: "uncertain")
        r = gate.step(d, np.array([0.5, 0.0, 0.0]))
        assert r.verdict == "uncertain" and r.replaced == replaced and r.cost == 0.0


def test_uncertified_fallback_is_marked_and_logged(caplog):
    m, d = _arm()
    gate = Gate(m, fallback=np.array([0.3, 0.0, 0.0]))
    _stub(gate, _unsafe_if_yaw_moves)  # the fallback moves the yaw joint too
    with caplog.at_level(logging.WARNING, logger="monitor.gate"):
        r = gate.step(d, np.array([1.0, 0.0, 0.0]))
    assert r.replaced and not r.fallback_certified and r.applied_verdict == "violation"
    assert r.info()["fallback_certified"] is False
    assert gate.summary()["fallback_uncertified"] == 1
    assert any("fallback" in rec.message for rec in caplog.records)


def test_callable_predictor_and_fallback_used():
    m, d = _arm()
    calls = []

    def predictor(data, ctrl, nstep):
        calls.append(np.array(ctrl))
        return Rollout(m).plan(data, ctrl, nstep)

    gate = Gate(m, predictor=predictor, fallback=lambda data: np.array([0.0, 0.1, 0.0]))
    _stub(gate, _unsafe_if_yaw_moves)
    r = gate.step(d, np.array([1.0, 0.0, 0.0]), nstep=2)
    assert len(calls) == 2 and np.array_equal(calls[1], [0.0, 0.1, 0.0])
    assert np.array_equal(r.applied_ctrl, [0.0, 0.1, 0.0])


def test_step_rejects_bad_ctrl():
    m, d = _arm()
    gate = Gate(m)
    with pytest.raises(InvalidInputError, match="shape"):
        gate.step(d, np.zeros(2))
    with pytest.raises(InvalidInputError, match="NaN"):
        gate.step(d, np.array([np.nan, 0, 0]))


# ----------------------------------------------------------------------------- with the real engine
def _agv_env():
    env = gym.make("monitor/AGV-v0", schedule="weaving").unwrapped
    env.reset(seed=0)
    return env


def test_reuse_gives_the_same_pair_results_and_skips_fixed_pairs():
    env = _agv_env()
    with_reuse, without = Gate(env.model), Gate(env.model, reuse=False)
    reused = []
    for rate in (1.0, 0.0, 0.0, 0.0, 1.0, 0.0):  # the vehicle moves, waits, moves, waits
        plan = env.planned_trajectory(np.array([rate]))
        before = with_reuse.stats["reused_pairs"]
        a, b = with_reuse.certify_plan(plan), without.certify_plan(plan)
        reused.append(with_reuse.stats["reused_pairs"] - before)
        assert a.verdict == b.verdict
        assert [p.geoms for p in a.pairs] == [p.geoms for p in b.pairs]
        assert [p.verdict for p in a.pairs] == [p.verdict for p in b.pairs]
        env.step(np.array([rate], dtype=np.float32))
    assert without.stats["reused_pairs"] == 0
    # a waiting vehicle's pairs with the (static) floor are reused once their pose was certified
    assert reused[0] == 0 and reused[1] == 0 and reused[2] > 0 and reused[3] > 0
    assert reused[4] == 0  # moving again: nothing fixed
    assert reused[5] == 0  # waiting at a NEW pose: first certification there


def test_budget_never_certifies_unfinished_work():
    from monitor.certify.common import Budget

    m, d = _arm()
    ctrl = np.array([np.arctan2(0.25, 0.45), 0.0, 0.0])  # from rest, the stretched arm swings at post_a
    free = Gate(m)
    plan = free.predict(d, ctrl, 60)  # 120 ms: a near miss (MuJoCo contact comes at ~128 ms)
    cert = free.certify_plan(plan)
    assert cert.stats["tests"] > 1
    tight = Gate(m, budget=Budget(tests=1))
    cert_b = tight.certify_plan(plan)
    assert cert_b.verdict != "certified"
    assert cert_b.verdict == "uncertain" or cert.verdict == "violation"
    per_step = Gate(m, budget=1)  # int = tests per window
    assert per_step.certify_plan(plan).verdict != "certified"


def test_block_on_tunnel_reuses_the_committed_tail():
    m = mujoco.MjModel.from_xml_path(str(scene_path("tunnel")))
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, 0)
    gate = Gate(m)
    xs = []
    for _ in range(30):
        r = gate.step(d, np.array([5.0]))
        xs.append(float(d.qpos[0]))
        assert r.fallback_certified
    assert max(xs) < -0.015  # never touches the wall
    s = gate.summary()
    assert s["replaced"] > 0 and s["tail_reused"] > 0 and s["fallback_uncertified"] == 0


def test_log_has_one_window_per_step(tmp_path):
    from monitor.log import reader, topics

    m = mujoco.MjModel.from_xml_path(str(scene_path("tunnel")))
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, 0)
    path = tmp_path / "gate.mcap"
    with Gate(m, log=path) as gate:
        reports = [gate.step(d, np.array([5.0])) for _ in range(8)]
    log = reader.read_log(path)
    assert log.complete
    certs = log.messages[topics.CERTIFICATE]
    # a replaced step also names the record of the motion that ran (h12ac: the fallback's window or
    # the committed brake's tail, once per tail); records are not step windows
    steps = [c for c in certs if "applied" not in c]
    records = {a["applied_window"] for a in log.messages[topics.ACTION] if a["replaced"]}
    assert len(steps) == len(reports) and len(certs) == len(reports) + len(records)
    assert (len(records) > 0) == any(r.replaced for r in reports)
    assert [c["verdict"] for c in steps] == [r.verdict for r in reports]


# ----------------------------------------------------------------------------- issue 11: the gate boundary
def _tunnel():
    m = mujoco.MjModel.from_xml_path(str(scene_path("tunnel")))
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, 0)
    return m, d


def test_step_with_non_numeric_ctrl_is_a_typed_error():
    m, d = _tunnel()
    with pytest.raises(InvalidInputError, match="ctrl"):
        Gate(m).step(d, "abc")


@pytest.mark.parametrize(("kwargs", "name"), [
    ({"log": 123}, "log"),
    ({"log": object()}, "log"),
    ({"log": "/proc/version/x.mcap"}, "log"),  # a directory that cannot be created
    ({"fallback": [1, 2, 3]}, "fallback"),  # the tunnel has one actuator
    ({"fallback": [np.nan]}, "fallback"),
    ({"fallback": "stop"}, "fallback"),
    ({"budget": {"seconds": "1"}}, "budget"),
    ({"budget": {"seconds": -1.0}}, "budget"),
    ({"budget": {"seconds": math.nan}}, "budget"),
    ({"budget": {"tests": 2.5}}, "budget"),
    ({"budget": {"tests": 0}}, "budget"),
    ({"budget": {"secs": 1.0}}, "budget"),
    ({"budget": -1.0}, "budget"),
    ({"tolerances": {"abs_pad": 0.0}}, "tolerances"),
])
def test_bad_gate_argument_raises_at_construction(kwargs, name):
    m, _ = _tunnel()
    with pytest.raises(InvalidInputError, match=name):
        Gate(m, **kwargs)


def _static_pair_model(gap: float = 0.1) -> mujoco.MjModel:
    """A sphere (r 0.1) on a slide joint at rest, a wall whose face is ``gap`` away; no gravity."""
    return mujoco.MjModel.from_xml_string(
        '<mujoco><option gravity="0 0 0"/><worldbody>'
        f'<geom name="wall" type="box" size="0.05 0.5 0.5" pos="{0.15 + gap} 0 0"/>'
        '<body name="b"><joint name="s" type="slide" axis="0 1 0"/>'
        '<geom name="ball" type="sphere" size="0.1"/></body></worldbody></mujoco>')


def test_reuse_cache_is_keyed_on_the_margin():
    """The issue's reproduction: a static pair 0.1 m apart, certified at margin 0, then margin 0.2."""
    from monitor import Plan, Scene, certify

    m = _static_pair_model(0.1)
    d = mujoco.MjData(m)
    gate = Gate(m, pairs="all", allowed=None, ongoing="violation")  # the plain certify contract
    assert gate.step(d, np.zeros(0)).verdict == "certified"
    assert gate.step(d, np.zeros(0)).certificate.stats.get("reused_pairs") == 1  # the cache is in use
    gate.margin = 0.2
    fresh = certify(Scene.from_model(m, pairs="all"), Plan([d.time, d.time + m.opt.timestep],
                                                             [d.qpos, d.qpos], m), margin=0.2)
    assert fresh.verdict == "violation"
    assert gate.step(d, np.zeros(0)).verdict == fresh.verdict
    gate.margin = 0.0
    assert gate.step(d, np.zeros(0)).verdict == "certified"


def test_reuse_cache_is_keyed_on_epsilon_tolerances_and_scene_version(monkeypatch):
    m = _static_pair_model(0.1)
    d = mujoco.MjData(m)
    gate = Gate(m, pairs="all")
    gate.step(d, np.zeros(0))

    def reused() -> int:
        return gate.step(d, np.zeros(0)).certificate.stats.get("reused_pairs", 0)

    assert reused() == 1
    gate.epsilon = 2e-3
    assert reused() == 0 and reused() == 1
    monkeypatch.setattr(gate.scene, "version", getattr(gate.scene, "version", 0) + 1, raising=False)
    assert reused() == 0 and reused() == 1
    from monitor.tolerances import Tolerances

    gate.tolerances = Tolerances(abs_pad=gate.tolerances.abs_pad * 2)
    assert reused() == 0 and reused() == 1
    with pytest.raises(InvalidInputError, match="margin"):
        gate.margin = -1.0
    with pytest.raises(InvalidInputError, match="epsilon"):
        gate.epsilon = 0.0


def test_zero_candidate_pairs_warn_once_at_construction():
    m = mujoco.MjModel.from_xml_string(
        '<mujoco><worldbody><body><freejoint/><geom type="sphere" size=".1"/></body></worldbody></mujoco>')
    with pytest.warns(UserWarning, match="no candidate pairs") as rec:
        gate = Gate(m)
    assert len(rec) == 1
    d = mujoco.MjData(m)
    report = gate.step(d, np.zeros(0))
    assert report.verdict == "certified" and report.info()["monitored_pairs"] == 0


def test_committed_tail_is_not_reused_after_a_setting_changed():
    """The committed brake's tail was certified at margin 0; at margin 0.5 (the wall is ~0.3 m away)
    the brake window must be re-certified, not taken from that tail."""
    m, d = _tunnel()
    gate = Gate(m, ongoing="violation")  # strict: within the margin at t0 is a violation
    assert gate.step(d, np.array([1.0])).verdict == "certified"  # commits a brake and its tail
    assert gate._tail is not None
    gate.margin = 0.5
    r = gate.step(d, np.array([1.0]))
    assert r.replaced and r.verdict == "violation"
    assert r.applied_verdict == "violation" and not r.fallback_certified
    assert gate.stats["tail_reused"] == 0


def test_callable_fallback_with_a_bad_return_value_is_a_typed_error():
    m, d = _tunnel()
    gate = Gate(m, margin=0.5, fallback=lambda data: [0.0, 0.0],  # the wall is within 0.5 m: blocked
                ongoing="violation")
    with pytest.raises(InvalidInputError, match="fallback"):
        gate.step(d, np.array([1.0]))
