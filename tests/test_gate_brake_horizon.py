"""The braking tail's horizon: passed through SafetyGate, validated with a typed error."""

import math

import gymnasium as gym
import mujoco
import numpy as np
import pytest

import monitor.envs  # noqa: F401  (registers monitor/*)
from monitor._paths import scene_path
from monitor.errors import InvalidInputError
from monitor.gate import Gate
from monitor.gym_gate import SafetyGate


@pytest.mark.parametrize("bad", [math.nan, math.inf, -0.1, 0.0, "x", None, True])
def test_bad_brake_horizon_is_a_typed_error(bad):
    model = mujoco.MjModel.from_xml_path(str(scene_path("tunnel")))
    with pytest.raises(InvalidInputError, match="brake_horizon"):
        Gate(model, brake_horizon=bad)


@pytest.mark.parametrize("bad", [math.nan, -1e-3, "x"])
def test_bad_brake_vel_tol_is_a_typed_error(bad):
    model = mujoco.MjModel.from_xml_path(str(scene_path("tunnel")))
    with pytest.raises(InvalidInputError, match="brake_vel_tol"):
        Gate(model, brake_vel_tol=bad)


def test_safety_gate_passes_the_horizon_to_its_gate():
    env = SafetyGate(gym.make("monitor/Arm-v0"), brake_horizon=0.1)
    timestep = env.unwrapped.model.opt.timestep
    assert env.gate.brake_steps == math.ceil(0.1 / timestep)
    assert env._saved_kwargs["brake_horizon"] == 0.1  # RecordConstructorArgs (gymnasium env specs)
    env.reset(seed=0)
    _, _, _, _, info = env.step(np.zeros(env.action_space.shape, np.float32))
    assert "safety" in info
    env.close()
    default = SafetyGate(gym.make("monitor/Arm-v0"))
    assert default.gate.brake_steps == math.ceil(0.25 / timestep)
    default.close()
    with pytest.raises(InvalidInputError, match="brake_horizon"):
        SafetyGate(gym.make("monitor/Arm-v0"), brake_horizon=-1.0)


def _tail_substeps(gate: Gate, model, steps: int) -> list[int]:
    """Substeps of each braking tail over ``steps`` seeded tunnel steps (the rollout's counter)."""
    d = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, d, 0)
    out = []
    for k in range(steps):
        before = gate._rollout.tail_substeps
        gate.step(d, np.array([3.0 if k < 4 else 0.5]), nstep=1)
        out.append(gate._rollout.tail_substeps - before)
    return out


def test_reassigned_horizon_takes_effect_like_a_constructed_one():
    """``gate.brake_horizon = h`` gives the tails of ``Gate(model, brake_horizon=h)`` (it was ignored)."""
    model = mujoco.MjModel.from_xml_path(str(scene_path("tunnel")))
    want = _tail_substeps(Gate(model, margin=0.001, brake_horizon=0.03), model, 6)
    gate = Gate(model, margin=0.001)
    gate.brake_horizon = 0.03
    assert gate.brake_horizon == 0.03 and gate.brake_steps == 3
    assert _tail_substeps(gate, model, 6) == want
    assert max(want) == 3  # the ball moves: tails run to the shorter horizon
    with pytest.raises(InvalidInputError, match="brake_horizon"):
        gate.brake_horizon = -1.0
    assert gate.brake_horizon == 0.03  # a refused value changes nothing


def test_horizon_stays_in_seconds_after_a_timestep_edit():
    model = mujoco.MjModel.from_xml_path(str(scene_path("tunnel")))
    gate = Gate(model, brake_horizon=0.25)
    n = gate.brake_steps
    model.opt.timestep /= 2  # a dynamics edit: twice the substeps for the same 0.25 s
    assert gate.brake_steps == math.ceil(0.25 / model.opt.timestep) == 2 * n
    model.opt.timestep = 0.0
    with pytest.raises(InvalidInputError, match="timestep"):
        _ = gate.brake_steps


def test_a_tail_too_long_to_buffer_is_a_typed_error_not_an_allocation():
    """brake_horizon / timestep beyond MAX_BRAKE_STEPS: the step raises InvalidInputError naming both
    settings before any tail buffer is sized by it; the gate's state and a sane horizon still work."""
    model = mujoco.MjModel.from_xml_path(str(scene_path("tunnel")))
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, 0)
    gate = Gate(model, margin=0.001)
    gate.brake_horizon = 1e9  # 1e11 substeps at the scene's 10 ms... would be terabytes of rows
    with pytest.raises(InvalidInputError, match="brake_horizon.*timestep.*MAX_BRAKE_STEPS"):
        gate.step(data, np.array([1.0]))
    model.opt.timestep = 1e-12  # the same through the timestep, with a reasonable horizon
    gate.brake_horizon = 0.25
    with pytest.raises(InvalidInputError, match="MAX_BRAKE_STEPS"):
        _ = gate.brake_steps
    model.opt.timestep = 0.01
    gate.step(data, np.array([1.0]))  # a sane setting steps again
    assert gate.stats["windows"] >= 1
