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
