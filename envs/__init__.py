"""Gymnasium environments shipped with monitor (MuJoCo scenes in ``models/``).

Importing this package registers (string entry points, one module per version):

* ``monitor/Arm-v0``: a 3-joint position-controlled arm with a mesh gripper among
  posts and a shelf; reach reward; ``planned_trajectory(action)``.
* ``monitor/Tunnel-v0``: a small fast sphere and a thin wall; at the env's
  timestep MuJoCo's discrete contacts let the sphere pass through the wall.
* ``monitor/AGV-v0``: Cameron's AGV and trays scene driven by a schedule.

Example::

    import gymnasium as gym
    import monitor.envs  # noqa: F401  (registers the ids)
    env = gym.make("monitor/Arm-v0")
"""

from __future__ import annotations

import gymnasium

_REGISTRY = {
    "monitor/Arm-v0": dict(entry_point="monitor.envs.arm_v0:ArmEnv", max_episode_steps=500),
    "monitor/Tunnel-v0": dict(entry_point="monitor.envs.tunnel_v0:TunnelEnv", max_episode_steps=100),
    "monitor/AGV-v0": dict(entry_point="monitor.envs.agv_v0:AgvEnv", max_episode_steps=400),
}


def register_all() -> None:
    """Register every env id (idempotent)."""
    for env_id, kwargs in _REGISTRY.items():
        if env_id not in gymnasium.registry:
            gymnasium.register(id=env_id, **kwargs)


register_all()

__all__ = ["register_all"]
