"""``monitor/Tunnel-v0``: a small fast sphere and a thin wall (tunnelling).

Scene: ``models/tunnel/scene.xml`` (see its README). A 1 cm sphere on a slide
joint along x, driven by a velocity servo; a 1 cm thick wall at x = 0. The
action is the commanded velocity (m/s, in [-6, 6]); one env step is one 10 ms
MuJoCo step. From the default start x0 = -0.32 m, commanding 5 m/s puts the
sphere at x = -0.025 m and then x = +0.025 m on consecutive steps: MuJoCo's
discrete contacts (evaluated at the step states) never see the wall, and the
sphere ends up behind it. The continuous motion between the two states crosses
the wall, which is what the gate's rollout predictor certifies.

Observation (2,): x (m) and velocity (m/s). Reward: ``-|x - goal|`` with the
goal behind the wall (x = 0.3 m). Never terminates by itself.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from gymnasium import spaces, utils
from gymnasium.envs.mujoco.mujoco_env import MujocoEnv

from monitor.envs.assets import scene
from monitor.gate import Rollout

TIMESTEP = 0.01
"""Model timestep (s), as in ``models/tunnel/scene.xml``."""
WALL_HALF_THICKNESS = 0.005
BALL_RADIUS = 0.01
GOAL_X = 0.3


class TunnelEnv(MujocoEnv, utils.EzPickle):
    """Shoot a small sphere at a thin wall.

    Args:
        x0: initial sphere position (m); the default makes the sphere tunnel at 5 m/s.
        reset_noise: half-width (m) of uniform noise on x0 (0: deterministic start).
        frame_skip: MuJoCo steps per env step.
        render_mode: gymnasium render mode.
        **kwargs: passed to :class:`MujocoEnv`.
    """

    metadata = {"render_modes": ["human", "rgb_array", "depth_array", "rgbd_tuple"], "render_fps": 100}

    def __init__(self, x0: float = -0.32, reset_noise: float = 0.0, frame_skip: int = 1,
                 render_mode: str | None = None, **kwargs: Any) -> None:
        utils.EzPickle.__init__(self, x0, reset_noise, frame_skip, render_mode, **kwargs)
        self.metadata = {**self.metadata, "render_fps": int(round(1.0 / (TIMESTEP * frame_skip)))}
        self.x0, self.reset_noise = float(x0), float(reset_noise)
        obs_space = spaces.Box(-np.inf, np.inf, shape=(2,), dtype=np.float64)
        MujocoEnv.__init__(self, str(scene("tunnel")), frame_skip, observation_space=obs_space,
                           render_mode=render_mode, **kwargs)
        self._planner = Rollout(self.model)

    def step(self, action: np.ndarray) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        """Command a velocity for ``frame_skip`` MuJoCo steps."""
        self.do_simulation(action, self.frame_skip)
        obs = self._get_obs()
        if self.render_mode == "human":
            self.render()
        return obs, -abs(float(obs[0]) - GOAL_X), False, False, {"behind_wall": bool(obs[0] > 0.0)}

    def reset_model(self) -> np.ndarray:
        """Sphere at rest at x0 (plus optional noise)."""
        noise = self.np_random.uniform(-self.reset_noise, self.reset_noise) if self.reset_noise else 0.0
        x = self.x0 + noise
        self.set_state(np.array([x]), np.zeros(1))
        return self._get_obs()

    def _get_obs(self) -> np.ndarray:
        return np.array([self.data.qpos[0], self.data.qvel[0]], dtype=np.float64)

    def planned_trajectory(self, action: np.ndarray) -> Any:
        """The :class:`monitor.Plan` of the next step (exact rollout on a scratch ``MjData``)."""
        return self._planner.plan(self.data, np.asarray(action), self.frame_skip)


__all__ = ["TunnelEnv", "WALL_HALF_THICKNESS", "BALL_RADIUS", "GOAL_X"]
