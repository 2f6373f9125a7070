"""SafetyGate with wrappers between the gate and the MuJoCo env (issue 11, section 2).

The gate must certify the control that ``MujocoEnv.do_simulation`` actually writes.
Oracle: on ``monitor/Tunnel-v0`` the sphere moves along x only, and within one
10 ms step the motion the certificate is about is the interpolation between the two
simulator states, so a window touches the wall exactly when the segment
[x_before, x_after] meets the band |x| <= wall half thickness + ball radius (closed
form, independent of the checkers).
"""

from __future__ import annotations

import gymnasium as gym
import mujoco
import numpy as np
import pytest
from gymnasium.wrappers import ClipAction, RecordEpisodeStatistics, RescaleAction

import monitor.envs  # noqa: F401  (registers monitor/Tunnel-v0)
from monitor.envs.tunnel_v0 import BALL_RADIUS, WALL_HALF_THICKNESS
from monitor.errors import InvalidInputError
from monitor.gym_gate import SafetyGate

BAND = WALL_HALF_THICKNESS + BALL_RADIUS


def _touches_wall(x0: float, x1: float) -> bool:
    return min(x0, x1) <= BAND and max(x0, x1) >= -BAND


def _run(env: gym.Env, action: np.ndarray, steps: int) -> list[tuple[float, float, str]]:
    """(x before, x after, verdict of the applied window) per step."""
    data = env.unwrapped.data
    env.reset(seed=0)
    out = []
    for _ in range(steps):
        x0 = float(data.qpos[0])
        info = env.step(action)[4]
        out.append((x0, float(data.qpos[0]), str(info.get("safety", {}).get("applied_verdict", ""))))
    return out


def _assert_sound(rows: list[tuple[float, float, str]]) -> None:
    for k, (x0, x1, verdict) in enumerate(rows):
        if _touches_wall(x0, x1):
            assert verdict != "certified", f"step {k}: x {x0:.4f} -> {x1:.4f} touches the wall, certified"


class Negate(gym.ActionWrapper):
    """A custom action wrapper: the env receives minus the action."""

    def action(self, action):
        return -np.asarray(action)


class OverridesStep(gym.Wrapper):
    """A plain wrapper whose step doubles the action (the gate cannot know)."""

    def step(self, action):
        return self.env.step(2.0 * np.asarray(action))


def test_rescale_action_tunnel_is_not_certified_through_the_wall():
    """The issue's reproduction: RescaleAction(-0.1, 0.1) makes the action 0.1 a 6 m/s command."""
    raw = _run(RescaleAction(gym.make("monitor/Tunnel-v0"), -0.1, 0.1), np.array([0.1]), 10)
    assert any(x1 > BAND for _, x1, _ in raw)  # ungated, the sphere tunnels (the test can fail)
    gated = SafetyGate(RescaleAction(gym.make("monitor/Tunnel-v0"), -0.1, 0.1))
    rows = _run(gated, np.array([0.1]), 20)
    _assert_sound(rows)
    assert all(x1 < -BAND for _, x1, _ in rows)  # blocked: never touches the wall


def test_custom_action_wrapper_is_composed():
    gated = SafetyGate(Negate(gym.make("monitor/Tunnel-v0")))
    rows = _run(gated, np.array([-6.0]), 20)  # the env receives +6 m/s, towards the wall
    _assert_sound(rows)
    assert all(x1 < -BAND for _, x1, _ in rows)
    assert rows[0][1] > rows[0][0]  # it did move towards the wall


def test_clip_action_is_composed():
    """ClipAction to a user-narrowed action space [3, 6]: the action -5 becomes +3 m/s.

    Every action (the zero fallback too) then drives the sphere into the wall: the gate
    cannot prevent it, but it must never call those windows certified.
    """
    inner = gym.make("monitor/Tunnel-v0")
    inner.unwrapped.action_space = gym.spaces.Box(3.0, 6.0, (1,), np.float32)
    gated = SafetyGate(ClipAction(inner))
    rows = _run(gated, np.array([-5.0]), 20)
    _assert_sound(rows)
    assert rows[0][1] > rows[0][0]  # it moved towards the wall ...
    assert any(_touches_wall(x0, x1) for x0, x1, _ in rows)  # ... and reached it (the check was exercised)


def test_predicted_control_is_what_the_env_writes():
    """Composed transform (outermost first) equals data.ctrl after every step."""
    env = SafetyGate(RecordEpisodeStatistics(RescaleAction(Negate(gym.make("monitor/Tunnel-v0")), -1.0, 1.0)),
                     on_violation="warn")
    env.reset(seed=0)
    rng = np.random.default_rng(0)
    for _ in range(10):
        a = rng.uniform(-1, 1, 1)
        env.step(a)
        expected = -(-6.0 + (a + 1.0) * 6.0)  # rescale [-1, 1] -> [-6, 6], then negate
        assert np.allclose(env.unwrapped.data.ctrl, expected, rtol=0, atol=1e-5)
        assert np.allclose(env.gate.last_report.plan.qpos[-1], env.unwrapped.data.qpos, rtol=0, atol=0)


@pytest.mark.parametrize("wrap", [OverridesStep, gym.wrappers.RepeatAction, gym.wrappers.StickyAction])
def test_wrapper_that_may_change_the_action_is_refused(wrap):
    kwargs = {"repeat_action_probability": 0.5} if wrap is gym.wrappers.StickyAction else {}
    kwargs = {"num_repeats": 2} if wrap is gym.wrappers.RepeatAction else kwargs
    env = wrap(gym.make("monitor/Tunnel-v0"), **kwargs)
    with pytest.raises(InvalidInputError, match=wrap.__name__):
        SafetyGate(env)


def test_action_transform_is_evaluated_once_per_step():
    """An action wrapper that is not a function of the action (a counter): the gate evaluates it once
    per step and the env receives exactly the control that was certified."""

    class Counting(gym.ActionWrapper):
        def __init__(self, env):
            super().__init__(env)
            self.k = 0

        def action(self, action):
            self.k += 1
            return np.asarray(action) + 1e-3 * self.k

    wrapper = Counting(gym.make("monitor/Tunnel-v0"))
    env = SafetyGate(wrapper, on_violation="warn")
    env.reset(seed=0)
    for k in range(1, 4):
        env.step(np.array([0.5]))
        assert wrapper.k == k
        assert np.array_equal(env.unwrapped.data.ctrl, env.gate.last_report.applied_ctrl)
        assert np.array_equal(env.unwrapped.data.ctrl, [0.5 + 1e-3 * k])
    assert "action" not in wrapper.__dict__  # the bypass is undone after the step


def test_env_step_that_changes_the_control_is_detected():
    """A MuJoCo env whose step doubles the action: the post-step check raises, never silent."""
    from monitor.envs.tunnel_v0 import TunnelEnv

    class Doubling(TunnelEnv):
        def step(self, action):
            return super().step(2.0 * np.asarray(action))

    env = SafetyGate(Doubling(), on_violation="warn")
    env.reset(seed=0)
    with pytest.raises(InvalidInputError, match="ctrl"):
        env.step(np.array([0.5]))


def test_brake_and_hold_fallback_work_through_rescale_action():
    """With RescaleAction the gate still commits a brake (control space) and applies it exactly."""
    env = SafetyGate(RescaleAction(gym.make("monitor/Tunnel-v0"), -1.0, 1.0))
    env.reset(seed=0)
    rows = []
    for _ in range(30):
        x0 = float(env.unwrapped.data.qpos[0])
        info = env.step(np.array([5.0 / 6.0]))[4]  # 5 m/s: would tunnel in two steps
        rows.append((x0, float(env.unwrapped.data.qpos[0]), str(info["safety"]["applied_verdict"])))
        assert info["safety"]["fallback_certified"]
    _assert_sound(rows)
    assert all(x1 < -BAND for _, x1, _ in rows)
    s = env.gate.summary()
    assert s["replaced"] > 0 and s["tail_reused"] > 0 and s["fallback_uncertified"] == 0


def test_array_fallback_is_an_action_through_the_wrappers():
    """fallback=[0.0] under RescaleAction(0, 1): the env receives -6 m/s (away from the wall)."""
    env = SafetyGate(RescaleAction(gym.make("monitor/Tunnel-v0"), 0.0, 1.0), fallback=np.array([0.0]),
                     margin=0.5, ongoing="violation")  # the wall is within 0.5 m: every proposal is blocked
    env.reset(seed=0)
    info = env.step(np.array([1.0]))[4]
    assert info["safety"]["replaced"]
    assert np.allclose(env.unwrapped.data.ctrl, [-6.0])


@pytest.mark.parametrize("clamp", [True, False])
def test_rollout_models_ctrlrange_clamping_as_mujoco(clamp):
    """Out-of-range actions: the gate's predicted end state equals the env's, bit for bit."""
    env = SafetyGate(gym.make("monitor/Tunnel-v0", x0=0.3), on_violation="warn")
    m = env.unwrapped.model
    if not clamp:
        m.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_CLAMPCTRL)
    env.reset(seed=0)
    speeds = []
    for a in (-100.0, 100.0, 7.0, -3.0):
        env.step(np.array([a]))
        plan = env.gate.last_report.plan
        assert np.array_equal(plan.qpos[-1], env.unwrapped.data.qpos)
        assert np.array_equal(env.unwrapped.data.ctrl, [a])  # MuJoCo clamps internally, ctrl is kept
        speeds.append(abs(float(env.unwrapped.data.qvel[0])))
    assert (speeds[0] <= 6.0 + 1e-9) == clamp  # the clamp really was (or was not) applied


def test_gym_make_chain_and_observation_wrappers_pass():
    env = SafetyGate(gym.wrappers.TransformObservation(
        RecordEpisodeStatistics(gym.make("monitor/Tunnel-v0")), lambda o: o, None))
    env.reset(seed=0)
    assert env.step(np.array([0.0]))[4]["safety"]["verdict"] == "certified"


def test_gate_over_a_gate_is_refused():
    with pytest.raises(InvalidInputError, match=r"wrapper monitor\.gym_gate\.SafetyGate"):
        SafetyGate(SafetyGate(gym.make("monitor/Tunnel-v0")))


def test_applied_ctrl_check_is_elementwise_float_equality():
    """The applied-control check after a step raises exactly when ``(data.ctrl == certified).all()`` is False.

    Oracle: numpy's element-wise ``==`` (NaN unequal to itself, -0.0 equal to 0.0), on seeded
    (nu,) pairs of Pusher-v5 controls that are equal, equal up to the sign of zero, NaN in the same
    place, or different in one entry.
    """
    env = SafetyGate(gym.make("Pusher-v5"), pairs="mujoco")
    env.reset(seed=0)
    ctrl = env.unwrapped.data.ctrl
    rng = np.random.default_rng(14)
    raised = {True: 0, False: 0}
    for t in range(200):
        certified = rng.uniform(-2.0, 2.0, size=ctrl.shape)
        certified[rng.random(ctrl.shape) < 0.2] = 0.0
        live = certified.copy()
        kind = t % 4
        if kind == 1:
            live[live == 0.0] = -0.0
        elif kind == 2:
            i = int(rng.integers(ctrl.size))
            live[i] = certified[i] = np.nan
        elif kind == 3:
            live[int(rng.integers(ctrl.size))] += 1e-12
        ctrl[:] = live
        want = not (ctrl == certified).all()
        try:
            env._check_applied_ctrl(certified)
            got = False
        except InvalidInputError:
            got = True
        assert got is want, (t, live, certified)
        raised[want] += 1
    assert min(raised.values()) >= 50, raised
    env.close()
