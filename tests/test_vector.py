"""SafetyGate inside SyncVectorEnv and AsyncVectorEnv."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

from monitor.certify.certificate import VERDICTS


def make_gated_tunnel():
    """The tunnel env (one candidate pair: cheap to certify), random velocity commands."""
    import monitor.envs  # noqa: F401  (registers the id in a subprocess too)
    from monitor.gym_gate import SafetyGate

    return SafetyGate(gym.make("monitor/Tunnel-v0", max_episode_steps=30, reset_noise=0.05), margin=0.002)


@pytest.mark.parametrize("vec", [gym.vector.SyncVectorEnv, gym.vector.AsyncVectorEnv])
def test_vector_envs_step_50_times(vec):
    venv = vec([make_gated_tunnel, make_gated_tunnel])
    try:
        venv.reset(seed=[1, 2])
        venv.action_space.seed(0)
        seen, replaced = 0, 0
        for _ in range(50):
            obs, rew, term, trunc, info = venv.step(venv.action_space.sample())
            assert obs.shape == (2, 2)
            s = info["safety"]
            assert s["verdict"].shape == (2,) and s["witness_point"].shape == (2, 3)
            assert s["checker"].shape[0] == 2 and info["cost"].shape == (2,)
            for i in range(2):
                if s["_verdict"][i] and s["verdict"][i] != "":  # "" = autoreset step
                    assert s["verdict"][i] in VERDICTS
                    seen += 1
                    replaced += int(s["replaced"][i])
                    if s["replaced"][i]:
                        assert s["applied_verdict"][i] in VERDICTS
        assert seen >= 90  # 100 sub-steps minus the autoreset steps
        assert not np.any(np.abs(obs[:, 0]) < 0.015)  # never inside the wall
    finally:
        venv.close()
