"""A gate with no candidate pair: certify's own trivial certificate without a Plan (issue 12).

Oracles: ``monitor.certify`` of the window's Plan under the gate's request (the certificate
the gate used to compute), and the gate's general path (``Gate._certify_nothing`` patched to
decline) for reports, ``info["safety"]``, states and errors.
"""

from __future__ import annotations

import warnings

import mujoco
import numpy as np
import pytest

from monitor import certify
from monitor.errors import InvalidInputError
from monitor.gate import Gate

# two hinge arms whose geoms cannot collide (contype = conaffinity = 0): pairs="mujoco" is empty
_NO_PAIRS = """
<mujoco>
  <option timestep="0.01"/>
  <worldbody>
    <body name="a"><joint name="ja" type="hinge" axis="0 0 1"/><geom size="0.05" fromto="0 0 0 0.3 0 0"
      type="capsule" contype="0" conaffinity="0"/></body>
    <body name="b" pos="0.2 0 0"><joint name="jb" type="slide" axis="0 1 0"/><geom size="0.05"
      contype="0" conaffinity="0"/></body>
    {extra}
  </worldbody>
  <actuator><position joint="ja" kp="20" ctrlrange="-1 1"/><motor joint="jb"/></actuator>
</mujoco>
"""


def _gate(extra: str = "", **kw):
    m = mujoco.MjModel.from_xml_string(_NO_PAIRS.format(extra=extra))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # "no candidate pairs" (the point of these tests)
        gate = Gate(m, allowed=None, **kw)
    return m, gate


def _without_wall(d: dict) -> dict:
    d = dict(d)
    d["stats"] = {k: v for k, v in d["stats"].items() if k != "wall_seconds"}
    return d


@pytest.mark.parametrize("brake", [True, False])
def test_zero_pair_certificates_are_certifys_own(brake, monkeypatch):
    """Every step's certificate equals certify(scene, window plan, request=gate.request) field
    for field (but wall time), carries the gate's request and says "nothing_checked"; no
    certify call and no Plan until a reader asks for one."""
    import monitor.certify.engine as engine

    m, gate = _gate(brake=brake, frame_skip=3)
    d = mujoco.MjData(m)
    rng = np.random.default_rng(5)
    calls = []
    real = engine.certify
    check = engine._check_model  # every certify of a zero-pair scene calls it (no memo there)
    # a spy on engine.certify itself would switch the shortcut off (see the last test)
    monkeypatch.setattr(engine, "_check_model", lambda *a: calls.append(a) or check(*a))
    for _ in range(12):
        r = gate.step(d, rng.uniform(-1.0, 1.0, m.nu))
        assert calls == []  # the trivial certificate: no certify call (the oracle's below are not counted)
        assert r.__dict__["_plan_store"]._plan is None  # the window's rows; no Plan built yet
        cert = r.certificate
        oracle = real(gate.scene, r.plan, request=gate.request)
        assert _without_wall(cert.to_dict()) == _without_wall(oracle.to_dict())
        assert cert.request is gate.request and cert.stats["nothing_checked"] is True
        assert str(cert.method) == "auto" and cert.pairs == () and cert.certified
        assert r.info()["monitored_pairs"] == 0 and r.info()["checker_mix"] == ""
        calls.clear()
    assert gate.stats["windows"] == 12 and gate.stats["pairs"] == 0


def test_zero_pair_safety_gate_reports_equal_the_general_path():
    """SafetyGate(Reacher-v5): observations, rewards, info["safety"] (every key, arrays by value
    and dtype) and the state after each step equal those of the general path."""
    gym = pytest.importorskip("gymnasium")
    from monitor.gym_gate import SafetyGate

    runs = []
    for fast in (True, False):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            env = SafetyGate(gym.make("Reacher-v5"))
        if not fast:
            env.gate._certify_nothing = lambda win: None  # the general path: Plan + certify
        obs, _ = env.reset(seed=3)
        env.action_space.seed(3)
        out = [obs]
        for _ in range(15):
            obs, rew, term, trunc, info = env.step(env.action_space.sample())
            s = info["safety"]
            out.append((obs, rew, term, trunc, {k: (v.dtype, v.tolist()) if isinstance(v, np.ndarray) else v
                                                for k, v in s.items()},
                        env.unwrapped.data.qpos.tobytes(), env.unwrapped.data.qvel.tobytes()))
        runs.append(out)
        env.close()
    fast, general = runs
    assert np.array_equal(fast[0], general[0])
    for a, b in zip(fast[1:], general[1:]):
        assert np.array_equal(a[0], b[0]) and a[1:] == b[1:]


@pytest.mark.parametrize("time", [np.nan, 1e300])
def test_zero_pair_bad_window_times_raise_as_before(time):
    """A window whose times are not finite and strictly increasing (NaN time; a time so large
    that t + dt == t) raises the Plan's InvalidInputError, the same message as the general path."""
    messages = []
    for fast in (True, False):
        m, gate = _gate()
        if not fast:
            gate._certify_nothing = lambda win: None
        d = mujoco.MjData(m)
        d.time = time
        with pytest.raises(InvalidInputError) as e:
            gate.step(d, np.zeros(m.nu))
        messages.append(str(e.value))
    assert messages[0] == messages[1] and "times" in messages[0]


def test_zero_pair_models_with_quaternions_or_mocap_take_the_general_path():
    """Ball / free joints (quaternion norms the Plan validates) or mocap bodies: no shortcut,
    and the certificate is still certify's own."""
    geom = '<geom size="0.05" contype="0" conaffinity="0"/>'
    for extra in (f'<body name="f" pos="0 0 1"><freejoint/>{geom}</body>',
                  f'<body name="mc" mocap="true" pos="0 0 2">{geom}</body>'):
        m, gate = _gate(extra)
        d = mujoco.MjData(m)
        r = gate.step(d, np.full(m.nu, 0.3))
        assert gate._certify_nothing(_rows_of(gate)) is None
        oracle = certify(gate.scene, r.plan, request=gate.request)
        assert _without_wall(r.certificate.to_dict()) == _without_wall(oracle.to_dict())


def _rows_of(gate):
    from monitor.gate import _WindowRows

    return _WindowRows(gate._rollout.window_rows, gate.model, mujoco.MjData(gate.model))


def test_zero_pair_log_has_one_record_per_window(tmp_path):
    """With a log, every window is written (its Plan built for the record) and review's reader
    gets one window per step with the trivial certificate."""
    pytest.importorskip("mcap")
    from monitor.log.reader import read_log

    m, gate = _gate(log=str(tmp_path / "z.mcap"))
    d = mujoco.MjData(m)
    for k in range(5):
        gate.step(d, np.full(m.nu, 0.1 * k))
    gate.close()
    certs = read_log(tmp_path / "z.mcap").certificates()
    assert len(certs) == 5
    assert all(c["verdict"] == "certified" and c["stats"]["nothing_checked"] and c["pairs"] == []
               for c in certs)


def test_a_replaced_certify_is_still_called_on_a_zero_pair_gate():
    """A gate whose _certify was replaced (a stub checker) keeps getting its verdicts: the
    shortcut stands only for Gate._certify's own result."""
    from monitor.certify.certificate import Certificate

    m, gate = _gate()
    seen = []

    def stub(plan):
        seen.append(plan.t0)
        return Certificate("violation", plan.window, 0.0, 1e-3, "auto", None, plan.t0, -np.inf), 1.0

    gate._certify = stub
    r = gate.step(mujoco.MjData(m), np.zeros(m.nu))
    assert seen and r.verdict == "violation" and r.replaced


def test_a_replaced_engine_certify_is_still_called_on_a_zero_pair_gate(monkeypatch):
    """``monitor.certify.engine.certify`` replaced (``Gate._certify`` calls it): the zero-pair
    shortcut stands only for the engine's own certify, so the replacement's verdict is used."""
    from monitor.certify import engine
    from monitor.certify.certificate import Certificate

    m, gate = _gate()
    seen = []

    def stub(scene, plan, **kw):
        seen.append(plan.t0)
        return Certificate("violation", plan.window, 0.0, 1e-3, "auto", None, plan.t0, -np.inf)

    monkeypatch.setattr(engine, "certify", stub)
    r = gate.step(mujoco.MjData(m), np.zeros(m.nu))
    assert seen and r.verdict == "violation" and r.replaced
