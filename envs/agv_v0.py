"""``monitor/AGV-v0``: Cameron's AGV and overhead trays, driven by a schedule.

Scene: ``models/agv_trays/scene.xml`` (or ``scene_skewed.xml``), schedules from
:func:`monitor.bench.extrusion_scenes.schedule` (see the scene's README). The
scene has three slide joints and no actuators: the env is *kinematic*. The
trays follow the schedule in real time t. The vehicle follows its own
scheduled path at a rate chosen by the agent: the action a (in [0, 2]) advances
the vehicle's schedule clock tau by ``a * dt`` per step (a = 1 reproduces the
schedule, a = 0 stops the vehicle where it is).

Because nothing is simulated, the motion of a step is known exactly in
advance: :meth:`AgvEnv.planned_trajectory` returns it as a :class:`monitor.Plan`
(waypoints at the step ends and at the schedule's breakpoints inside the step),
so gate it with ``SafetyGate(env, predictor="plan")``. Each step then sets
qpos to the plan's last waypoint and advances ``data.time``.

Observation (5,): t (s), tau (s), agv_x, tray_y, tray_z (m).
Reward: the vehicle's progress along its path in the step (m). Terminates when
the vehicle reaches the end of its path (tau >= end of the schedule).
"""

from __future__ import annotations

from typing import Any

import gymnasium
import mujoco
import numpy as np
from gymnasium import spaces

from monitor.envs.assets import scene


class AgvEnv(gymnasium.Env):
    """AGV under overhead trays; the agent sets the vehicle's schedule rate.

    Args:
        schedule: ``"weaving"`` (narrow miss, certified at rate 1) or ``"straight"``
            (the crate hits tray 1 at t = 29/3 s at rate 1).
        skewed: use the copy of the scene with all axes rotated.
        dt: seconds per env step.
        render_mode: unused (kept for the gymnasium signature); only None.
    """

    metadata = {"render_modes": [], "render_fps": 10}

    def __init__(self, schedule: str = "weaving", skewed: bool = False, dt: float = 0.1,
                 render_mode: str | None = None) -> None:
        from monitor.bench.extrusion_scenes import schedule as get_schedule

        path = scene("agv_trays")
        if skewed:
            path = path.parent / "scene_skewed.xml"
        self.model = mujoco.MjModel.from_xml_path(str(path))
        self.data = mujoco.MjData(self.model)
        self.fullpath = str(path)
        sch = get_schedule(schedule)
        self._times = np.asarray(sch["times"], float)
        self._qpos = np.asarray(sch["qpos"], float)
        self.schedule_name = schedule
        self.dt = float(dt)
        self.frame_skip = 1
        self.metadata = {**self.metadata, "render_fps": int(round(1.0 / self.dt))}
        self.render_mode = render_mode
        self.action_space = spaces.Box(0.0, 2.0, shape=(1,), dtype=np.float32)
        self.observation_space = spaces.Box(-np.inf, np.inf, shape=(5,), dtype=np.float64)
        self.tau = 0.0

    # ------------------------------------------------------------------ schedule
    def _agv_x(self, tau: np.ndarray | float) -> np.ndarray:
        return np.interp(tau, self._times, self._qpos[:, 0])

    def _trays(self, t: np.ndarray | float) -> tuple[np.ndarray, np.ndarray]:
        return np.interp(t, self._times, self._qpos[:, 1]), np.interp(t, self._times, self._qpos[:, 2])

    def _rate(self, action: Any) -> float:
        a = float(np.asarray(action, dtype=np.float64).reshape(-1)[0])
        if not np.isfinite(a):
            raise ValueError(f"action must be finite, got {action!r}")
        return float(np.clip(a, self.action_space.low[0], self.action_space.high[0]))

    def _waypoints(self, action: Any) -> tuple[np.ndarray, np.ndarray, float]:
        """Times (K,), qpos (K, 3) of the next step and the vehicle clock at its end."""
        t0, a = float(self.data.time), self._rate(action)
        t1 = t0 + self.dt
        tau0 = self.tau
        tau1 = tau0 + a * self.dt
        ts = {t0, t1}
        for bp in self._times:  # breakpoints of the trays (real time) and of the vehicle (tau)
            if t0 < bp < t1:
                ts.add(float(bp))
            if a > 0 and tau0 < bp < tau1:
                tb = t0 + (bp - tau0) / a
                if t0 < tb < t1:
                    ts.add(float(tb))
        times = np.array(sorted(ts))
        taus = tau0 + a * (times - t0)
        tray_y, tray_z = self._trays(times)
        qpos = np.stack([self._agv_x(taus), tray_y, tray_z], axis=1)
        return times, qpos, tau1

    def planned_trajectory(self, action: Any) -> Any:
        """The :class:`monitor.Plan` of the next step under ``action`` (exact)."""
        from monitor.motion.plan import Plan

        times, qpos, _ = self._waypoints(action)
        return Plan(times, qpos, model=self.model)

    # ------------------------------------------------------------------ gymnasium API
    def _obs(self) -> np.ndarray:
        q = self.data.qpos
        return np.array([self.data.time, self.tau, q[0], q[1], q[2]], dtype=np.float64)

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None
              ) -> tuple[np.ndarray, dict[str, Any]]:
        """Start of the schedule (t = tau = 0)."""
        super().reset(seed=seed)
        mujoco.mj_resetData(self.model, self.data)
        self.tau = float(self._times[0])
        self.data.time = float(self._times[0])
        self.data.qpos[:] = self._qpos[0]
        mujoco.mj_forward(self.model, self.data)
        return self._obs(), {"schedule": self.schedule_name}

    def step(self, action: Any) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        """Advance the trays by dt and the vehicle by ``action * dt`` of its schedule."""
        times, qpos, tau1 = self._waypoints(action)
        x0 = float(self.data.qpos[0])
        self.data.qpos[:] = qpos[-1]
        self.data.time = float(times[-1])
        self.tau = float(tau1)
        mujoco.mj_forward(self.model, self.data)
        obs = self._obs()
        terminated = bool(self.tau >= self._times[-1])
        return obs, float(abs(obs[2] - x0)), terminated, False, {"tau": self.tau}


__all__ = ["AgvEnv"]
