"""The gate certifies window + braking tail with one call when that is as strong as two (issue 12, item 5).

Oracle: the same gate with the joint call switched off (``gate._joint_tail = False``: today's
two calls, window then tail). On seeded episodes (tunnel ``Gate.step``; ``SafetyGate`` on
Pusher-v5 and monitor/Arm-v0) every step's report must agree: verdict, applied control,
replaced, applied verdict, brake verdict, terminated, and the simulated state after the step.
The episodes are chosen so that both paths are exercised: windows settled by the joint call,
and windows where it falls back (rejections, a tail that is not certified).
"""

from __future__ import annotations

import gymnasium as gym
import mujoco
import numpy as np
import pytest

import monitor.envs  # noqa: F401  (registers monitor/Arm-v0)
from monitor._paths import scene_path
from monitor.gate import Gate
from monitor.gym_gate import SafetyGate


def _key(r):
    return (str(r.verdict), r.applied_ctrl.tobytes(), r.replaced, str(r.applied_verdict),
            str(r.brake_verdict), r.terminated, r.unsafe, r.fallback_certified)


def _tunnel_run(joint: bool, steps: int):
    m = mujoco.MjModel.from_xml_path(str(scene_path("tunnel")))
    rng = np.random.default_rng(1)
    ctrls = [np.array([rng.uniform(-6.0, 6.0)]) for _ in range(steps // 20 + 1)]
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, 0)
    gate = Gate(m)
    gate._joint_tail = joint
    out = []
    for k in range(steps):
        if k % 100 == 99:
            mujoco.mj_resetDataKeyframe(m, d, 0)
            gate.reset()
        r = gate.step(d, ctrls[k // 20])
        out.append((_key(r), d.qpos.tobytes(), d.qvel.tobytes()))
    return out, gate.summary()


def _gym_run(env_id: str, joint: bool, steps: int, **kw):
    env = SafetyGate(gym.make(env_id), **kw)
    env.gate._joint_tail = joint
    env.action_space.seed(0)
    acts = [env.action_space.sample() for _ in range(steps)]
    env.reset(seed=0)
    out = []
    for a in acts:
        _, _, term, trunc, info = env.step(a)
        r = env.gate.last_report
        d = env.unwrapped.data
        out.append((_key(r), d.qpos.tobytes(), d.qvel.tobytes(), info["safety"]["verdict"]))
        if term or trunc:
            env.reset(seed=1)
    summary = env.gate.summary()
    env.close()
    return out, summary


def _assert_same(new, old):
    for k, (a, b) in enumerate(zip(new, old)):
        assert a == b, f"step {k}: joint gate {a[0]} != two-call gate {b[0]}"
    assert len(new) == len(old)


def test_tunnel_joint_call_gives_the_two_call_reports():
    new, s_new = _tunnel_run(True, 120)
    old, s_old = _tunnel_run(False, 120)
    _assert_same(new, old)
    assert s_old["joint"] == 0
    # both paths ran: windows settled by one call, and fallbacks (rejected proposals)
    assert s_new["joint"] > 0 and s_new["replaced"] > 0
    assert s_new["replaced"] == s_old["replaced"] and s_new["brake_rejected"] == s_old["brake_rejected"]


@pytest.mark.parametrize("env_id, kw, steps", [
    ("Pusher-v5", {"pairs": "mujoco"}, 40),
    ("monitor/Arm-v0", {}, 40),
])
def test_safety_gate_joint_call_gives_the_two_call_reports(env_id, kw, steps):
    new, s_new = _gym_run(env_id, True, steps, **kw)
    old, s_old = _gym_run(env_id, False, steps, **kw)
    _assert_same(new, old)
    assert s_new["joint"] > 0 and s_old["joint"] == 0
    assert s_new["windows"] == s_old["windows"] == steps


_SLIDER = """
<mujoco model="slider">
  <worldbody>
    <geom name="wall" type="box" size="0.05 0.5 0.5" pos="0 0 0"/>
    <body name="ball" pos="0 0 0">
      <joint name="x" type="slide" axis="1 0 0"/>
      <geom name="ball" type="sphere" size="0.05" mass="1"/>
    </body>
  </worldbody>
</mujoco>
"""


def _slider_plans(gaps_window, gaps_tail):
    """Window and tail plans of the ball (gap to the wall's face at x = 0.05, m)."""
    from monitor.motion.plan import Plan

    m = mujoco.MjModel.from_xml_string(_SLIDER)
    x = lambda g: [[0.1 + v] for v in g]  # noqa: E731  ball centre = face + radius + gap
    tw = np.linspace(0.0, 0.1, len(gaps_window))
    tb = np.linspace(0.1, 0.2, len(gaps_tail))
    return m, Plan(tw, x(gaps_window), m), Plan(tb, x(gaps_tail), m)


def _joint(gate, plan, tail):
    return gate._certify_joint(plan, np.c_[plan.times, plan.qpos], np.c_[tail.times, tail.qpos],
                               plan.mocap_pos, plan.mocap_quat)


def test_joint_call_refuses_an_ongoing_contact_judged_at_the_window_start():
    # Within the margin at t0 (ongoing, may not close by more than penetration_tol), clear at
    # t1, then the tail comes back to 4 cm < margin. The tail alone (clear at its start, so the
    # full margin applies) is a violation; the joint plan, judged against t0's depth, certifies.
    m, plan, tail = _slider_plans([0.03, 0.1], [0.1, 0.04])
    gate = Gate(m, pairs="all", allowed=None, margin=0.05)
    joint_cert = gate._certify(type(plan)(np.r_[plan.times, tail.times[1:]],
                                          np.r_[plan.qpos, tail.qpos[1:]], m))[0]
    assert joint_cert.certified and joint_cert.stats.get("ongoing", 0) == 1  # the weaker joint answer
    assert gate._certify(tail)[0].verdict == "violation"  # what two calls say
    assert _joint(gate, plan, tail) is None  # so the gate falls back to two calls
    assert gate.stats["joint"] == 0


def test_joint_call_settles_both_parts_when_every_pair_keeps_the_margin():
    m, plan, tail = _slider_plans([0.03, 0.1], [0.1, 0.04])
    for ongoing in ("deepen", "violation"):
        gate = Gate(m, pairs="all", allowed=None, margin=0.02, ongoing=ongoing)
        out = _joint(gate, plan, tail)
        assert out is not None
        w, b, _ = out
        assert w.certified and b.certified
        assert w.window == plan.window and b.window == tail.window
        assert w.stats["joint_window"] == b.stats["joint_window"] == [0.0, 0.2]
        assert 0.02 < w.clearance <= 0.03 + 1e-9  # a lower bound over both parts
    # a part that does not start where the window ends is never joined
    m, plan, tail = _slider_plans([0.03, 0.1], [0.09, 0.04])
    assert _joint(Gate(m, pairs="all", allowed=None, margin=0.02), plan, tail) is None
    # nor a tail that violates the margin (the joint call is not certified)
    m, plan, tail = _slider_plans([0.03, 0.1], [0.1, 0.01])
    gate = Gate(m, pairs="all", allowed=None, margin=0.02)
    assert _joint(gate, plan, tail) is None and gate.stats["joint"] == 0


def test_report_plan_is_the_rollout_plan_built_on_first_read():
    import dataclasses

    from monitor.motion.plan import Plan

    m = mujoco.MjModel.from_xml_path(str(scene_path("tunnel")))
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, 0)
    ref = Gate(m).predict(d, np.array([2.0]))  # Rollout.plan of the same window
    gate = Gate(m)
    r = gate.decide(d, np.array([2.0]))
    assert gate.stats["joint"] == 1
    assert "_plan_store" in r.__dict__ and not isinstance(r.__dict__["_plan_store"], Plan)  # not built yet
    p = r.plan
    assert isinstance(p, Plan) and r.plan is p  # built once, then kept
    assert np.array_equal(p.times, ref.times) and np.array_equal(p.qpos, ref.qpos)
    assert np.array_equal(p.mocap_pos, ref.mocap_pos) and np.array_equal(p.mocap_quat, ref.mocap_quat)
    assert dataclasses.replace(r, stepped=True).plan is p
    with pytest.raises(dataclasses.FrozenInstanceError):
        r.plan = None
    # Gate.step's report carries the same lazily built plan
    r2 = gate.step(d, np.array([2.0]))
    assert r2.stepped and isinstance(r2.plan, Plan) and r2.plan.t0 == r.time


def test_a_custom_predictor_is_used_and_never_joined():
    m = mujoco.MjModel.from_xml_path(str(scene_path("tunnel")))
    calls = []

    class Mine(Gate):
        def predict(self, data, ctrl, nstep=None):
            calls.append(nstep)
            return super().predict(data, ctrl, nstep)

    def pred(data, ctrl, nstep):
        calls.append(-nstep)
        return Gate(m).predict(data, ctrl, nstep)

    for gate in (Mine(m), Gate(m, predictor=pred)):
        d = mujoco.MjData(m)
        mujoco.mj_resetDataKeyframe(m, d, 0)
        calls.clear()
        r = gate.decide(d, np.array([2.0]))
        assert calls and r.verdict == "certified" and r.brake_verdict == "certified"
        assert gate.stats["joint"] == 0  # its window may not be the rollout's: two calls


def _tail_of(m, tail):
    """A gate ``_Tail`` from a tail Plan (its rows: time, qpos, zero qvel)."""
    from monitor.gate import _Tail

    return _Tail(np.c_[tail.times, tail.qpos, np.zeros((len(tail.times), m.nv))], m, mujoco.MjData(m))


def test_a_joint_witness_in_the_tail_rejects_the_brake_as_the_tails_own_call_does():
    # Clear window, then the tail drives the ball 2 cm into the wall: the joint call is a
    # violation with its witness in the tail, and the gate may reject the brake without a
    # second certify of the tail. Oracle: the tail's own certificate (a separate call).
    m, plan, tail = _slider_plans([0.1, 0.1], [0.1, -0.02])
    for ongoing in ("deepen", "violation"):
        gate = Gate(m, pairs="all", allowed=None, margin=0.01, ongoing=ongoing)
        assert _joint(gate, plan, tail) is None
        w = gate._joint_witness
        assert w is not None and tail.t0 <= w.time <= tail.t1 and w.distance < 0.01
        own = gate._certify(tail)[0]
        assert own.verdict == "violation" and gate.is_unsafe(own.verdict)
        assert gate._tail_refuted(w, _tail_of(m, tail))
    # under unsafe="violation" an uncertain tail would be accepted: the tail is certified again
    gate = Gate(m, pairs="all", allowed=None, margin=0.01, unsafe="violation")
    assert _joint(gate, plan, tail) is None and gate._joint_witness is not None
    assert not gate._tail_refuted(gate._joint_witness, _tail_of(m, tail))
    # a witness in the window (or none) is not kept
    m, plan, tail = _slider_plans([0.1, 0.1, -0.02, 0.1], [0.1, 0.1])
    gate = Gate(m, pairs="all", allowed=None, margin=0.01)
    assert _joint(gate, plan, tail) is None and gate._joint_witness is None


def test_a_joint_witness_does_not_refute_a_tail_that_starts_in_an_ongoing_contact():
    # The tail starts 5 mm from the wall (inside the 1 cm margin) and ends at 2 mm: a plain
    # violation of the margin, but under ongoing="deepen" the tail's own call judges the pair
    # as an ongoing contact at ITS start and certifies it (it never penetrates). The joint
    # witness must then not reject the brake; under ongoing="violation" it must.
    from monitor.certify.certificate import Witness

    m, plan, tail = _slider_plans([0.1, 0.005], [0.005, 0.002])
    w = Witness(float(tail.times[-1]), ("ball", "wall"), np.zeros(3), 0.002)
    deepen = Gate(m, pairs="all", allowed=None, margin=0.01, ongoing="deepen")
    own = deepen._certify(tail)[0]
    assert own.verdict == "certified" and own.stats.get("ongoing", 0) == 1   # the oracle
    assert not deepen._tail_refuted(w, _tail_of(m, tail))
    plain = Gate(m, pairs="all", allowed=None, margin=0.01, ongoing="violation")
    assert plain._certify(tail)[0].verdict == "violation"
    assert plain._tail_refuted(w, _tail_of(m, tail))


def test_arm_tails_refuted_by_the_joint_witness_are_unsafe_by_their_own_call():
    # Every tail the gate rejects from the joint call's witness is certified again here by its
    # own call (the oracle): it must be unsafe, with the same verdict label.
    env = SafetyGate(gym.make("monitor/Arm-v0"))
    gate = env.gate
    seen = []
    refuted = gate._tail_refuted

    def check(witness, tail):
        out = refuted(witness, tail)
        if out:
            own = gate._certify(tail.plan)[0]
            seen.append((str(own.verdict), gate.is_unsafe(own.verdict)))
        return out

    gate._tail_refuted = check
    env.action_space.seed(0)
    acts = [env.action_space.sample() for _ in range(40)]
    env.reset(seed=0)
    for a in acts:
        env.step(a)
    env.close()
    assert seen and gate.stats["tail_refuted"] == len(seen)
    assert all(s == ("violation", True) for s in seen), seen


def test_the_joint_call_skips_the_ongoing_rule_and_its_certificates_carry_the_gates_request():
    # The joint call runs under ongoing="violation" (a certificate the rule changed is never
    # used); a certified joint call is what the gate's own request gives, and carries that request.
    m, plan, tail = _slider_plans([0.03, 0.1], [0.1, 0.04])
    gate = Gate(m, pairs="all", allowed=None, margin=0.02, ongoing="deepen")
    assert gate._plain_request().ongoing == "violation" and gate._plain_request() is gate._plain_request()
    assert gate._plain_request().replace(ongoing="deepen") == gate.request
    w, b, _ = _joint(gate, plan, tail)
    assert w.request is gate.request and b.request is gate.request
    joint = type(plan)(np.r_[plan.times, tail.times[1:]], np.r_[plan.qpos, tail.qpos[1:]], m)
    own = gate._certify(joint)[0]       # the oracle: one call under the gate's request
    assert own.certified and own.clearance == w.clearance == b.clearance
    assert own.stats["tests"] == w.stats["tests"] and own.pairs == w.pairs
    plain = Gate(m, pairs="all", allowed=None, margin=0.02, ongoing="violation")
    assert plain._plain_request() is plain.request
