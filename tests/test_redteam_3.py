"""Red team 3: ``certified`` for a motion that collides, at the gate layer (issue 12, h12ag).

Oracles are independent of the checkers: a sphere on a slide joint along x moves toward a
box wall that MuJoCo does not collide (contype 0, an explicitly monitored pair), so it passes
through it; the signed distance of the sphere to the wall's face is ``x_face - x - r`` in
closed form. Along one window the sphere moves monotonically (constant force), so the
smallest distance of the applied window is at one of its end states, which the test reads
from the live data (the motion that actually ran).
"""

from __future__ import annotations

import gymnasium as gym
import mujoco
import numpy as np
import pytest
from gymnasium.envs.mujoco.mujoco_env import MujocoEnv

from monitor.errors import InvalidInputError
from monitor.gate import Gate
from monitor.gym_gate import SafetyGate

RADIUS = 0.05
FACE_X = 0.15  # wall's face (m): the box spans x in [0.15, 0.25]
DT = 0.002

_XML = f"""
<mujoco>
  <option timestep="{DT}" gravity="0 0 0"/>
  <worldbody>
    <body name="ball" pos="0 0 0">
      <joint name="x" type="slide" axis="1 0 0"/>
      <geom name="ball" type="sphere" size="{RADIUS}" mass="1" contype="0" conaffinity="0"/>
    </body>
    <geom name="wall" type="box" pos="{FACE_X + 0.05} 0 0" size="0.05 0.3 0.3" contype="0" conaffinity="0"/>
  </worldbody>
  <actuator><motor name="push" joint="x" ctrlrange="-1 1"/></actuator>
</mujoco>
"""


def _model() -> mujoco.MjModel:
    return mujoco.MjModel.from_xml_string(_XML)


def _distance(x: float) -> float:
    """Closed-form signed distance (m) of the ball at slide position ``x`` to the wall's face."""
    return FACE_X - x - RADIUS


# --------------------------------------------------------------------------- dynamics edit, committed brake
def test_committed_brake_is_not_reused_after_a_gravity_edit():
    """A committed braking tail certified under one gravity is not the motion under another.

    Step 1 (no gravity): the ball coasts at 0.05 m/s toward the wall 0.1 m away; the window and
    its 0.25 s braking tail (motor off: it coasts 12.5 mm) are certified, the tail committed.
    Then ``model.opt.gravity`` points at the wall (500 m/s^2). Step 2's proposal collides and is
    replaced by the committed brake (control 0), whose window is a waypoint range of the
    committed tail in time, qpos, qvel and mocap: on main the gate reused the tail's
    certificate (``applied_verdict == "certified"``) although under the new gravity that window
    carries the ball 0.1 m, through the wall.
    """
    m = _model()
    d = mujoco.MjData(m)
    d.qvel[0] = 0.05
    gate = Gate(m, pairs=[("ball", "wall")], frame_skip=10)
    r1 = gate.step(d, np.zeros(1))
    assert r1.verdict == "certified" and not r1.replaced and r1.brake_verdict == "certified"
    m.opt.gravity[:] = (500.0, 0.0, 0.0)
    x0 = float(d.qpos[0])
    r2 = gate.step(d, np.zeros(1))
    x1 = float(d.qpos[0])
    assert r2.replaced
    assert min(_distance(x0), _distance(x1)) < -0.01  # the oracle: the applied window went through
    assert r2.applied_verdict != "certified", (x0, x1, r2.applied_verdict)
    assert not r2.fallback_certified


def test_committed_brake_is_still_reused_without_an_edit():
    """The replay check keeps the exact reuse: an unchanged model reuses the committed tail.

    The ball coasts at 0.4 m/s; step 1's window and tail are certified (the tail ends 5 mm
    before contact). Step 2 pushes (+1 N): its own tail reaches the wall, so it is replaced by
    the committed brake, whose window is the committed tail's: the tail's certificate is reused
    (``tail_reused``) and the ball stays clear.
    """
    m = _model()
    d = mujoco.MjData(m)
    d.qpos[0] = -0.013
    d.qvel[0] = 0.4  # window 8 mm + tail 0.25 s coasting 0.1 m: ends at x = 0.095, 5 mm before contact
    gate = Gate(m, pairs=[("ball", "wall")], frame_skip=10)
    r1 = gate.step(d, np.zeros(1))
    assert r1.verdict == "certified" and r1.brake_verdict == "certified"
    r2 = gate.step(d, np.ones(1))  # push: the tail after it reaches the wall
    assert r2.replaced and r2.applied_verdict == "certified"
    assert gate.stats["tail_reused"] == 1
    x = float(d.qpos[0])
    assert _distance(x) > 0.0


# --------------------------------------------------------------------------- SafetyGate: substeps per step
BAND = 0.015  # Tunnel-v0: wall half thickness 5 mm + ball radius 1 cm


def _tunnel_touches(x0: float, x1: float) -> bool:
    """Closed form: a window from x0 to x1 (continuous in x) meets the wall's band |x| <= BAND."""
    return min(x0, x1) <= BAND and max(x0, x1) >= -BAND


def _tunnel_rows(env: gym.Env, steps: int) -> list[tuple[float, float, str]]:
    d = env.unwrapped.data
    out = []
    for _ in range(steps):
        x0 = float(d.qpos[0])
        info = env.step(np.array([5.0]))[4]
        out.append((x0, float(d.qpos[0]), str(info["safety"]["applied_verdict"])))
    return out


def test_frame_skip_changed_after_construction_is_certified_as_it_runs():
    """``env.unwrapped.frame_skip`` set after the gate was built (a curriculum, a user's tuning).

    On main the gate kept the construction-time count (1 substep of 10 ms) and certified that
    window while the env simulated 10 substeps: step 0 at 5 m/s went from x = -0.32 to 0.175,
    through the wall, reported ``applied_verdict == "certified"``. Now every step certifies
    the live count; the oracle (closed form on x before and after) finds no certified window
    that meets the wall.
    """
    import monitor.envs  # noqa: F401  (registers monitor/Tunnel-v0)

    env = SafetyGate(gym.make("monitor/Tunnel-v0"))
    env.reset(seed=0)
    env.unwrapped.frame_skip = 10
    rows = _tunnel_rows(env, 4)
    env.close()
    for k, (x0, x1, verdict) in enumerate(rows):
        assert not (_tunnel_touches(x0, x1) and verdict == "certified"), (k, x0, x1, verdict)
    assert env.gate.frame_skip == 10


@pytest.mark.parametrize("bad", [0, -1, 2.5, True, "3"])
def test_invalid_live_frame_skip_is_a_typed_error(bad):
    import monitor.envs  # noqa: F401

    env = SafetyGate(gym.make("monitor/Tunnel-v0"))
    env.reset(seed=0)
    env.unwrapped.frame_skip = bad
    with pytest.raises(InvalidInputError, match="frame_skip"):
        env.step(np.array([0.0]))
    env.close()


class _TwiceTunnel(MujocoEnv):
    """A user's MujocoEnv whose step simulates two windows (calls ``do_simulation`` twice)."""

    metadata = {"render_modes": ["human", "rgb_array", "depth_array", "rgbd_tuple"], "render_fps": 100}

    def __init__(self) -> None:
        from monitor.envs.assets import scene

        MujocoEnv.__init__(self, str(scene("tunnel")), 1,
                           observation_space=gym.spaces.Box(-np.inf, np.inf, shape=(2,), dtype=np.float64))

    def step(self, action):
        self.do_simulation(action, self.frame_skip)
        self.do_simulation(action, self.frame_skip)
        obs = np.array([self.data.qpos[0], self.data.qvel[0]])
        return obs, 0.0, False, False, {}

    def reset_model(self):
        self.set_state(np.array([-0.32]), np.zeros(1))
        return np.array([-0.32, 0.0])


def test_env_step_that_simulates_two_windows_is_detected():
    """On main the second ``do_simulation`` ran uncertified and silently (the ctrl check passes:
    the control is the certified one); now the step raises InvalidInputError naming the time."""
    env = SafetyGate(_TwiceTunnel())
    env.reset(seed=0)
    with pytest.raises(InvalidInputError, match="data.time"):
        env.step(np.array([1.0]))
    env.close()
