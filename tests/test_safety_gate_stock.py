"""SafetyGate on stock, unmodified Gymnasium MuJoCo environments."""

from __future__ import annotations

import warnings

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

from monitor.certify.certificate import VERDICTS
from monitor.errors import InvalidInputError
from monitor.gym_gate import SafetyGate

STOCK = ["Pusher-v5", "Reacher-v5", "Ant-v5"]
STEPS = 200  # the issue-5 acceptance figure; ~55 s for the three envs on an idle 2-core machine


def _run(env_id, steps):
    env = SafetyGate(gym.make(env_id), pairs="all")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # "use env.unwrapped" and box advisories
        check_env(env, skip_render_check=True)
    obs, info = env.reset(seed=0)
    assert set(info["safety"]) == set(env.step(env.action_space.sample())[4]["safety"])
    env.action_space.seed(0)
    counts = dict.fromkeys(VERDICTS, 0)
    for _ in range(steps):
        obs, rew, term, trunc, info = env.step(env.action_space.sample())
        v = info["safety"]["verdict"]
        assert v in VERDICTS
        counts[v] += 1
        # issue 13: cost of the applied window; the proposal's cost is a separate key
        assert info["cost"] == (1.0 if info["safety"]["applied_verdict"] == "violation" else 0.0)
        assert info["safety"]["proposal_cost"] == (1.0 if v == "violation" else 0.0)
        assert info["safety"]["checker"].shape == (env.gate.npairs,)
        if term or trunc:
            env.reset()
    assert sum(counts.values()) == steps
    env.close()


@pytest.mark.parametrize("env_id", STOCK)
def test_check_env_and_200_random_steps(env_id):
    _run(env_id, STEPS)


def test_step_tuple_and_spec_roundtrip():
    env = SafetyGate(gym.make("Reacher-v5"), pairs="all", margin=0.01)
    env.reset(seed=1)
    out = env.step(env.action_space.sample())
    assert len(out) == 5
    spec = env.spec
    assert spec.additional_wrappers[-1].name == "SafetyGate"
    assert spec.additional_wrappers[-1].kwargs["margin"] == 0.01
    env.close()


def test_timing_opt_in():
    env = SafetyGate(gym.make("Reacher-v5"), pairs="all", timing=True)
    env.reset(seed=0)
    info = env.step(env.action_space.sample())[4]
    assert info["safety"]["certify_us"] > 0
    assert env.gate.last_report.certify_us == info["safety"]["certify_us"]
    env.close()


def test_clear_error_without_mujoco():
    with pytest.raises(InvalidInputError, match="MuJoCo env"):
        SafetyGate(gym.make("CartPole-v1"))


def test_plan_predictor_needs_planned_trajectory():
    with pytest.raises(InvalidInputError, match="planned_trajectory"):
        SafetyGate(gym.make("Reacher-v5"), predictor="plan")


def test_rollout_predictor_matches_env_step_states():
    """The certified plan ends exactly at the state the env reaches."""
    env = SafetyGate(gym.make("Pusher-v5"), pairs="all", on_violation="warn")
    env.reset(seed=2)
    env.action_space.seed(2)
    u = env.unwrapped
    for _ in range(5):
        env.step(env.action_space.sample())
        plan = env.gate.last_report.plan
        assert np.array_equal(plan.qpos[-1], u.data.qpos)
    env.close()
