"""Tunnelling: the gate sees the wall crossing that MuJoCo's discrete contacts miss."""

from __future__ import annotations

import gymnasium as gym
import mujoco
import numpy as np

import monitor.envs  # noqa: F401
from monitor.envs.tunnel_v0 import BALL_RADIUS, WALL_HALF_THICKNESS
from monitor.gym_gate import SafetyGate

FIRE = np.array([5.0], dtype=np.float32)
BAND = BALL_RADIUS + WALL_HALF_THICKNESS  # the ball overlaps the wall iff |x| < BAND


def _mujoco_ncon_at(model, x):
    """MuJoCo's own contacts with the ball at position x (independent MjData)."""
    d = mujoco.MjData(model)
    d.qpos[0] = x
    mujoco.mj_forward(model, d)
    return d.ncon


def test_warn_reports_violation_on_the_crossing_step_that_mujoco_misses():
    env = SafetyGate(gym.make("monitor/Tunnel-v0"), on_violation="warn")
    obs, _ = env.reset(seed=0)
    m = env.unwrapped.model
    xs, verdicts, infos = [float(obs[0])], [], []
    for _ in range(12):
        obs, _, _, _, info = env.step(FIRE)
        xs.append(float(obs[0]))
        verdicts.append(info["safety"]["verdict"])
        infos.append(info)
    xs = np.array(xs)
    k = int(np.argmax(xs > 0))  # step k-1 -> k crosses the wall
    assert k > 0 and xs[k - 1] < -BAND and xs[k] > BAND, "the motion crosses the wall within one step"
    # MuJoCo: no contact at either step state, nor anywhere along the episode
    assert _mujoco_ncon_at(m, xs[k - 1]) == 0 and _mujoco_ncon_at(m, xs[k]) == 0
    assert all(_mujoco_ncon_at(m, x) == 0 for x in xs)
    # the gate: violation exactly on the crossing step, with a witness on the wall
    crossing = infos[k - 1]
    assert verdicts[k - 1] == "violation"
    assert crossing["cost"] == 1.0 and not crossing["safety"]["replaced"]
    assert sorted(crossing["safety"]["witness_geoms"].tolist()) == ["ball", "wall"]
    t0, t1 = crossing["safety"]["time"], crossing["safety"]["time"] + m.opt.timestep
    assert t0 <= crossing["safety"]["witness_time"] <= t1
    assert abs(crossing["safety"]["witness_point"][0]) <= BAND
    # steps strictly before the crossing: the ball stays clear, the gate certifies them
    for i in range(k - 1):
        if xs[i + 1] < -BAND:
            assert verdicts[i] == "certified", (i, verdicts[i])
    env.close()


def test_block_never_crosses():
    env = SafetyGate(gym.make("monitor/Tunnel-v0"), on_violation="block")
    obs, _ = env.reset(seed=0)
    xs, replaced = [float(obs[0])], 0
    for _ in range(100):
        obs, _, _, _, info = env.step(FIRE)
        xs.append(float(obs[0]))
        replaced += int(info["safety"]["replaced"])
        assert info["safety"]["fallback_certified"]
    xs = np.array(xs)
    assert np.all(xs < -BAND), "the ball never touches nor crosses the wall"
    assert replaced > 0, "the gate had to intervene"
    env.close()


def test_ungated_crosses():
    """Control: the same policy without the gate ends behind the wall."""
    env = gym.make("monitor/Tunnel-v0")
    obs, _ = env.reset(seed=0)
    for _ in range(20):
        obs, *_ = env.step(FIRE)
    assert obs[0] > BAND
