"""Settings of ``Gate`` / ``SafetyGate`` reassigned after construction act or are refused (red team 4).

Every test here failed on the base commit b036d4c: ``pairs`` / ``allowed`` / ``hazards`` / ``allow``
(and ``model``, ``reference_qpos`` once the scene was built) were plain attributes, silently ignored
after the first decision while the log's pair policy read them live; the other settings were set
without validation. Oracles: the closed-form distance of a ball on a slide joint to a box wall
(MuJoCo does not collide them: contype 0, an explicitly monitored pair), on the live data.
"""

from __future__ import annotations

import gymnasium as gym
import mujoco
import numpy as np
import pytest

from monitor.errors import InvalidInputError
from monitor.gate import Gate
from monitor.gym_gate import SafetyGate

BALL_R, WALL_HALF, WALL_X = 0.01, 0.005, 0.05

_XML = f"""<mujoco><option timestep="0.002" gravity="0 0 0"/><worldbody>
<geom name="wall" type="box" pos="{WALL_X} 0 0" size="{WALL_HALF} 0.2 0.2" contype="0" conaffinity="0"/>
<geom name="far" type="sphere" pos="0 1 0" size="0.01" contype="0" conaffinity="0"/>
<body name="ball"><joint name="x" type="slide" axis="1 0 0"/>
  <geom name="ball" type="sphere" size="{BALL_R}" mass="0.01" contype="0" conaffinity="0"/></body>
</worldbody><actuator><velocity name="vx" joint="x" kv="10" ctrlrange="-6 6"/></actuator></mujoco>"""


def _gap(x0: float, x1: float) -> float:
    """Closed-form least distance (m) of the ball to the wall while x goes monotonically x0 -> x1."""
    nearest = min(max(WALL_X, min(x0, x1)), max(x0, x1))
    return abs(WALL_X - nearest) - WALL_HALF - BALL_R


def _setup(**kw):
    m = mujoco.MjModel.from_xml_string(_XML)
    d = mujoco.MjData(m)
    kw.setdefault("pairs", [("ball", "wall")])
    return m, d, Gate(m, **kw)


# ----------------------------------------------------------------------------- what is certified: fixed
@pytest.mark.parametrize("name, value", [
    ("pairs", [("ball", "far")]), ("pairs", "all"), ("allowed", None), ("hazards", ["far"]),
    ("allow", [("ball", "wall")]), ("model", "other")])
@pytest.mark.parametrize("decided", [False, True])
def test_pair_policy_cannot_be_reassigned(name, value, decided):
    """Base: ``gate.allow = [("ball", "wall")]`` after the first step was accepted and ignored (the
    wall stayed checked) while a log opened later recorded the new policy; now a typed error naming
    the setting, before and after the scene is built. The gate still checks what it was built with:
    a window into the wall (closed form) is not certified."""
    m, d, gate = _setup()
    if decided:
        gate.decide(d, np.zeros(1))
    if name == "model":
        value = mujoco.MjModel.from_xml_string(_XML)
    with pytest.raises(InvalidInputError, match=rf"Gate\.{name} cannot be reassigned.*new Gate\({name}="):
        setattr(gate, name, value)
    d.qpos[0], d.qvel[0] = WALL_X - 0.02, 0.0
    r = gate.decide(d, np.array([6.0]), nstep=10)
    x1 = float(r.plan.qpos[-1, 0])
    assert _gap(float(d.qpos[0]), x1) < 0.0 and r.verdict != "certified", (x1, r.verdict)
    assert gate.scene.candidate_pairs and gate.model is m


def test_list_settings_are_frozen_against_in_place_edits():
    """Base: ``gate.hazards.append(...)`` edited the list the log's policy is read from, after the scene
    had been built from it. Now lists are stored as tuples (pairs: tuples of tuples)."""
    m, d, gate = _setup(hazards=["ball"], allow=[["ball", "far"]])
    assert gate.pairs == (("ball", "wall"),) and gate.hazards == ("ball",)
    assert gate.allow == (("ball", "far"),)
    with pytest.raises(AttributeError):
        gate.hazards.append("wall")  # type: ignore[attr-defined]
    meta = gate._policy_metadata()  # the pair policy the log records (review --verify re-derives it)
    assert meta["pairs"] == "(('ball', 'wall'),)" and meta["hazards"] == ["ball"]
    assert meta["allow"] == [["ball", "far"]]


def test_reference_qpos_is_validated_and_fixed_once_the_scene_is_built():
    """Base: any value was accepted, and a pose assigned after the first decision changed nothing
    (allowed='auto' had been resolved) while the log would record it."""
    m, d, gate = _setup()
    with pytest.raises(InvalidInputError, match="reference_qpos"):
        gate.reference_qpos = np.zeros(2)
    with pytest.raises(InvalidInputError, match="reference_qpos"):
        gate.reference_qpos = np.array([np.nan])
    gate.reference_qpos = [0.01]
    assert isinstance(gate.reference_qpos, np.ndarray) and gate.reference_qpos.tolist() == [0.01]
    gate.decide(d, np.zeros(1))
    assert gate._policy_metadata()["reference_qpos"] == [0.01]
    with pytest.raises(InvalidInputError, match="reference_qpos cannot be reassigned"):
        gate.reference_qpos = np.zeros(1)
    assert gate._policy_metadata()["reference_qpos"] == [0.01]


def test_log_path_is_read_only(tmp_path):
    """Base: ``gate.log_path = other`` was accepted and the gate kept writing the first file."""
    m, d, gate = _setup(log=tmp_path / "run.mcap")
    gate.decide(d, np.zeros(1))
    assert gate.log_path == tmp_path / "run.mcap"
    with pytest.raises(InvalidInputError, match=r"Gate\.log_path cannot be reassigned.*new Gate\(log="):
        gate.log_path = tmp_path / "other.mcap"
    gate.decide(d, np.zeros(1))
    gate.close()
    assert gate.log_path == tmp_path / "run.mcap" and not (tmp_path / "other.mcap").exists()


# ----------------------------------------------------------------------------- how it gates: act, validated
@pytest.mark.parametrize("name, bad", [
    ("frame_skip", 0), ("frame_skip", 2.5), ("frame_skip", True), ("reuse", "yes"), ("brake", None),
    ("predictor", "plan"), ("on_violation", "stop"), ("unsafe", "maybe"), ("fallback", np.zeros(2)),
    ("fallback", [np.nan]), ("brake_vel_tol", -1.0), ("brake_vel_tol", float("nan"))])
def test_reassigned_settings_are_validated(name, bad):
    """Base: every one of these was stored as given and failed later (or never)."""
    m, d, gate = _setup()
    before = getattr(gate, name)
    with pytest.raises(InvalidInputError, match=name):
        setattr(gate, name, bad)
    assert getattr(gate, name) is before


def test_reassigned_settings_act_from_the_next_step():
    """Each reassigned setting is the one the next step uses (oracle: the closed-form gap and
    ``data.time``); base: the same, but only after the refusals above (which it lacked)."""
    m, d, gate = _setup(brake=False)
    with pytest.raises(InvalidInputError, match="frame_skip"):
        gate.frame_skip = 0
    gate.frame_skip = 4
    r = gate.step(d, np.array([0.0]))
    assert r.stepped and d.time == pytest.approx(4 * m.opt.timestep, abs=1e-15)
    gate.frame_skip = 10
    d.qpos[0], d.qvel[0] = WALL_X - 0.02, 0.0
    x0 = float(d.qpos[0])
    r = gate.decide(d, np.array([6.0]))  # 10 substeps: through the wall (closed form)
    assert _gap(x0, float(r.plan.qpos[-1, 0])) < 0.0 and r.replaced and not r.terminated
    gate.fallback = np.array([-1.0])     # a new array fallback (brake off: no committed brake)
    r = gate.decide(d, np.array([6.0]))
    assert r.replaced and r.applied_ctrl.tolist() == [-1.0]
    gate.on_violation = "terminate"
    assert gate.decide(d, np.array([6.0])).terminated
    gate.on_violation = "warn"
    r = gate.decide(d, np.array([6.0]))
    assert not r.replaced and r.applied_ctrl.tolist() == [6.0]


# ----------------------------------------------------------------------------- SafetyGate
def _tunnel():
    import monitor.envs  # noqa: F401  (registers monitor/Tunnel-v0)

    env = SafetyGate(gym.make("monitor/Tunnel-v0"))
    env.reset(seed=0)
    return env


@pytest.mark.parametrize("name, arg", [("predictor_mode", "predictor"), ("user_fallback", "fallback"),
                                       ("action_chain", "env")])
def test_safety_gate_fixed_settings_refuse(name, arg):
    """Base: ``env.user_fallback = np.array([...])`` left the gate's array fallback as built (ignored);
    ``predictor_mode`` switched the predictor without the commit hook and brake choices made for it."""
    env = _tunnel()
    with pytest.raises(InvalidInputError, match=rf"SafetyGate\.{name} cannot be reassigned.*{arg}="):
        setattr(env, name, np.zeros(1) if name == "user_fallback" else "plan")
    env.close()


def test_safety_gate_refuses_a_gate_frame_skip_the_env_does_not_step():
    """Base: ``env.gate.frame_skip = 3`` was overwritten by the env's count at the next step
    (silently ignored). The env's ``frame_skip`` is what runs: set that (it acts, tested in
    test_redteam_3); a gate count equal to the env's is accepted."""
    env = _tunnel()
    fs = env.unwrapped.frame_skip
    env.gate.frame_skip = fs + 2
    with pytest.raises(InvalidInputError, match="set env.unwrapped.frame_skip"):
        env.step(np.array([0.0]))
    env.gate.frame_skip = fs
    env.step(np.array([0.0]))
    env.unwrapped.frame_skip = fs + 1
    env.gate.frame_skip = fs + 1
    t0 = env.unwrapped.data.time
    env.step(np.array([0.0]))
    assert env.unwrapped.data.time == pytest.approx(t0 + (fs + 1) * env.unwrapped.model.opt.timestep)
    env.close()
