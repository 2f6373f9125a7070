"""``monitor/Arm-v0``: a 3-joint arm with a mesh gripper among posts and a shelf.

Scene: ``models/arm/scene.xml`` (see its README). Three hinge joints
(shoulder yaw, shoulder pitch, elbow) driven by position actuators; the action
is the (3,) vector of joint targets (rad), clipped to the actuators' ctrlrange.
Each step integrates ``frame_skip`` substeps of 2 ms (default 10: dt = 20 ms).

Observation (12,): joint positions (3, rad), joint velocities (3, rad/s),
gripper point (3, m, world) and target point (3, m, world).
Reward: ``-||gripper point - target||`` (m). Never terminates by itself.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from gymnasium import spaces, utils
from gymnasium.envs.mujoco.mujoco_env import MujocoEnv

from monitor.envs.assets import scene
from monitor.gate import Rollout

TIMESTEP = 0.002
"""Model timestep (s), as in ``models/arm/scene.xml``."""


class ArmEnv(MujocoEnv, utils.EzPickle):
    """Reach a target with a 3-joint arm among obstacles.

    Args:
        frame_skip: substeps per env step (dt = 0.002 * frame_skip s).
        reset_noise: half-width (rad) of the uniform noise on the initial joints.
        render_mode: gymnasium render mode.
        **kwargs: passed to :class:`MujocoEnv` (width, height, camera, ...).
    """

    metadata = {"render_modes": ["human", "rgb_array", "depth_array", "rgbd_tuple"], "render_fps": 50}

    def __init__(self, frame_skip: int = 10, reset_noise: float = 0.05, render_mode: str | None = None,
                 **kwargs: Any) -> None:
        utils.EzPickle.__init__(self, frame_skip, reset_noise, render_mode, **kwargs)
        self.metadata = {**self.metadata, "render_fps": int(round(1.0 / (TIMESTEP * frame_skip)))}
        self.reset_noise = float(reset_noise)
        obs_space = spaces.Box(-np.inf, np.inf, shape=(12,), dtype=np.float64)
        MujocoEnv.__init__(self, str(scene("arm")), frame_skip, observation_space=obs_space,
                           render_mode=render_mode, **kwargs)
        self._grip = self.model.site("grip").id
        self._planner = Rollout(self.model)

    def step(self, action: np.ndarray) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        """Apply joint targets for ``frame_skip`` substeps."""
        self.do_simulation(action, self.frame_skip)
        obs = self._get_obs()
        dist = float(np.linalg.norm(obs[6:9] - obs[9:12]))
        if self.render_mode == "human":
            self.render()
        return obs, -dist, False, False, {"distance": dist}

    def reset_model(self) -> np.ndarray:
        """Noisy initial joints at rest, and a new target in front of the arm."""
        rng = self.np_random
        qpos = self.init_qpos + rng.uniform(-self.reset_noise, self.reset_noise, size=self.model.nq)
        self.set_state(qpos, np.zeros(self.model.nv))
        r, yaw, z = rng.uniform(0.35, 0.6), rng.uniform(-0.6, 0.6), rng.uniform(0.2, 0.55)
        self.data.mocap_pos[0] = (r * np.cos(yaw), r * np.sin(yaw), z)
        return self._get_obs()

    def _get_obs(self) -> np.ndarray:
        return np.concatenate([self.data.qpos, self.data.qvel, self.data.site_xpos[self._grip],
                               self.data.mocap_pos[0]]).astype(np.float64)

    def planned_trajectory(self, action: np.ndarray) -> Any:
        """The :class:`monitor.Plan` of the next step under ``action``.

        The env's controller is the position servo, so its plan is the exact
        prediction of the next ``frame_skip`` substeps (a rollout on a scratch
        ``MjData``; the live state is not touched).
        """
        return self._planner.plan(self.data, np.asarray(action), self.frame_skip)


__all__ = ["ArmEnv"]
