"""SafetyGate at its boundary (issue 11): typed errors, zero candidate pairs, one log path in vector envs."""

from __future__ import annotations

import warnings
from functools import partial

import gymnasium as gym
import numpy as np
import pytest

import monitor.envs  # noqa: F401  (registers monitor/Tunnel-v0)
from monitor.errors import InvalidInputError
from monitor.gym_gate import SafetyGate


@pytest.mark.parametrize("action", [np.zeros(3), np.zeros((1, 1)), "abc", np.array([np.nan])])
def test_step_with_a_bad_action_is_a_typed_error(action):
    env = SafetyGate(gym.make("monitor/Tunnel-v0"))
    env.reset(seed=0)
    with pytest.raises(InvalidInputError, match="action"):
        env.step(action)


@pytest.mark.parametrize(("kwargs", "name"), [
    ({"log": 123}, "log"),
    ({"fallback": [1.0, 2.0, 3.0]}, "fallback"),
    ({"budget": {"seconds": "1"}}, "budget"),
    ({"budget": {"tests": -3}}, "budget"),
])
def test_bad_argument_raises_at_construction(kwargs, name):
    with pytest.raises(InvalidInputError, match=name):
        SafetyGate(gym.make("monitor/Tunnel-v0"), **kwargs)


def test_zero_candidate_pairs_warn_at_construction_and_info_says_so():
    """Reacher-v5 under pairs='mujoco' has no candidate pair: nothing is monitored."""
    with pytest.warns(UserWarning, match="Reacher-v5.*no candidate pairs"):
        env = SafetyGate(gym.make("Reacher-v5"))
    _, info = env.reset(seed=0)
    assert info["safety"]["monitored_pairs"] == 0
    info = env.step(env.action_space.sample())[4]
    assert info["safety"]["monitored_pairs"] == 0 and info["safety"]["verdict"] == "certified"
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        env = SafetyGate(gym.make("Reacher-v5"), pairs="all")  # something to check: no warning
    env.reset(seed=0)
    assert env.step(env.action_space.sample())[4]["safety"]["monitored_pairs"] == env.gate.npairs > 0


@pytest.mark.parametrize("mode", ["sync", "async"])
def test_vector_env_with_one_log_path_keeps_every_window(tmp_path, mode):
    """gym.make_vec with one log= path: each sub-env writes its own file, no window is lost."""
    from monitor.log import topics
    from monitor.log.reader import read_log

    path = tmp_path / "x.mcap"
    steps = 12
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # "log ... is being written by another gate" (expected)
        venv = gym.make_vec("monitor/Tunnel-v0", num_envs=2, vectorization_mode=mode,
                            wrappers=[partial(SafetyGate, log=str(path))])
        try:
            venv.reset(seed=[1, 2])
            for _ in range(steps):
                venv.step(np.full((2, 1), 0.5, dtype=np.float32))
        finally:
            venv.close()
    files = sorted(tmp_path.glob("x*.mcap"))
    assert [f.name for f in files] == ["x.1.mcap", "x.mcap"]
    for f in files:
        log = read_log(f)
        assert log.complete, f
        certs = log.messages[topics.CERTIFICATE]
        assert len(certs) == steps, (f, len(certs))
        assert all(c["verdict"] == "certified" for c in certs)


def test_second_gate_on_a_claimed_path_writes_a_sibling(tmp_path):
    """Two gates in one process on one path: the first keeps it, the second gets x.1.mcap."""
    import mujoco

    from monitor._paths import scene_path
    from monitor.gate import Gate

    m = mujoco.MjModel.from_xml_path(str(scene_path("tunnel")))
    path = tmp_path / "x.mcap"
    a, b = Gate(m, log=path), Gate(m, log=path)
    da, db = mujoco.MjData(m), mujoco.MjData(m)
    a.step(da, np.zeros(1))
    with pytest.warns(UserWarning, match="another gate"):
        b.step(db, np.zeros(1))
    assert a.log_path == path and b.log_path == tmp_path / "x.1.mcap"
    a.close()
    b.close()
    c = Gate(m, log=path)  # released on close: the path is free again
    c.step(mujoco.MjData(m), np.zeros(1))
    assert c.log_path == path
    c.close()


def test_callable_fallback_with_a_bad_return_value_is_a_typed_error():
    env = SafetyGate(gym.make("monitor/Tunnel-v0"), margin=0.5, fallback=lambda env, obs: [0.0, 0.0],
                     ongoing="violation")
    env.reset(seed=0)
    with pytest.raises(InvalidInputError, match="fallback"):
        env.step(np.array([1.0]))


def test_log_directory_is_created_or_a_typed_error(tmp_path):
    path = tmp_path / "new" / "dir" / "tunnel.mcap"
    env = SafetyGate(gym.make("monitor/Tunnel-v0"), log=str(path))
    env.reset(seed=0)
    env.step(np.zeros(env.action_space.shape))
    env.close()
    assert path.is_file()
    blocker = tmp_path / "a_file"
    blocker.write_text("not a directory")
    with pytest.raises(InvalidInputError, match="log"):
        SafetyGate(gym.make("monitor/Tunnel-v0"), log=str(blocker / "x.mcap"))
