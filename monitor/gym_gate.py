"""Gymnasium wrapper: certify the next ``env.step`` before it happens and gate the action.

:class:`SafetyGate` is a thin adapter over :class:`monitor.gate.Gate`: it finds
the ``MjModel``/``MjData`` through ``env.unwrapped``, turns the gate's
decision into an ``env.step`` call, and reports in ``info``:

* ``info["safety"]`` (an API, layout version ``info["safety"]["version"]`` = 2,
  :data:`monitor.gate_policy.SAFETY_INFO_VERSION`): the fixed-shape dict of
  :meth:`monitor.gate.StepReport.info` (verdict, checker per pair, witness, earliest
  time, clearance, replaced, ...), plus

  - ``proposal_cost``: 1.0 when the *proposed* action's window has a confirmed
    violation on a monitored pair (blocked or not), else 0.0;
  - ``intervened``: True when the proposed action was replaced;
  - ``block_reason``: ``""`` or, comma-joined, ``"proposal_violation"`` |
    ``"proposal_uncertain"`` | ``"brake_tail_uncertified"``, then
    ``"fallback_uncertain"`` when the replacement did not certify either.
* ``info["cost"]``: the cost of the transition that happened (safety-gymnasium's
  convention in the 5-tuple API): 1.0 when the *applied* action's window has a
  confirmed violation on a monitored (hazard) pair, else 0.0.

Defaults that work on stock envs: the pairs checked are MuJoCo's candidate pairs
minus the allowed-contact matrix computed from the model at the first ``reset``
(``allowed="auto"``, :mod:`monitor.acm`; its reference pose is the state after that
reset, so resting contacts of the env's real start state are Default, not those of
``qpos0``), and contacts already present when a window starts may deepen up to
``penetration_tol`` (``ongoing="deepen"``, :mod:`monitor.certify.ongoing`); every new
contact is checked at full margin. ``SafetyGate.describe()`` says what is monitored
(also logged at the first reset; a gate that checks nothing warns once).

The action is assumed to be written to ``data.ctrl`` by the env (what
gymnasium's ``MujocoEnv.do_simulation`` does) when ``predictor="rollout"``.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import gymnasium
import mujoco
import numpy as np

from monitor.certify.ongoing import DEFAULT_PENETRATION_TOL
from monitor.errors import InvalidInputError
from monitor.gate import Gate, StepReport, safety_info
from monitor.gate_policy import safety_keys


class SafetyGate(gymnasium.Wrapper, gymnasium.utils.RecordConstructorArgs):
    """Certify-then-step wrapper for MuJoCo gymnasium environments.

    Args:
        env: a gymnasium env whose ``unwrapped`` has ``model`` (MjModel) and
            ``data`` (MjData), e.g. any ``MujocoEnv``.
        predictor: ``"rollout"`` (scratch rollout of ``frame_skip`` substeps with
            ``ctrl = action``), ``"plan"`` (``env.unwrapped.planned_trajectory(action)``)
            or a callable ``predictor(env, obs, action) -> Plan``.
        pairs: candidate pairs (``"mujoco"``, ``"all"`` or geom-name pairs).
        margin: clearance (m) that counts as safe.
        epsilon: certification tolerance (m).
        on_violation: ``"block" | "terminate" | "warn"`` (see :class:`monitor.Gate`).
        fallback: None (hold position where actuators allow, else zeros; the zero
            action, clipped to the action space, when the action is not ``data.ctrl``),
            an action array, or a callable ``fallback(env, obs) -> action``.
        budget: per-step work limit (seconds float, tests int, dict or Budget).
        log: None, an ``.mcap`` path or a :class:`monitor.log.MonitorLog`.
        unsafe: ``"uncertain"`` (default: anything not certified is unsafe) or ``"violation"``.
        timing: add ``info["safety"]["certify_us"]`` (wall time, µs). Off by default
            because a wall time differs between identical runs, which fails
            gymnasium's step-determinism check in ``check_env``; the time is always
            in ``gate.last_report.certify_us`` and ``gate.summary()``.
        brake: recoverability check with a committed brake (see :class:`monitor.Gate`).
        allowed, hazards, allow, ongoing, penetration_tol: pair policy and the
            ongoing-contact rule, see :class:`monitor.Gate` (defaults ``"auto"``, None,
            None, ``"deepen"``, 0.005 m).

    Raises:
        InvalidInputError: if ``env.unwrapped`` has no MuJoCo model/data or an option is invalid.
    """

    def __init__(self, env: gymnasium.Env, *, predictor: str | Callable[..., Any] = "rollout",
                 pairs: Any = "mujoco", margin: float = 0.0, epsilon: float = 1e-3,
                 on_violation: str = "block", fallback: Any = None, budget: Any = None, log: Any = None,
                 unsafe: str = "uncertain", timing: bool = False, brake: bool = True,
                 allowed: Any = "auto", hazards: Any = None, allow: Any = None, ongoing: str = "deepen",
                 penetration_tol: float = DEFAULT_PENETRATION_TOL) -> None:
        gymnasium.utils.RecordConstructorArgs.__init__(
            self, predictor=predictor, pairs=pairs, margin=margin, epsilon=epsilon,
            on_violation=on_violation, fallback=fallback, budget=budget, log=log, unsafe=unsafe,
            timing=timing, brake=brake, allowed=allowed, hazards=hazards, allow=allow, ongoing=ongoing,
            penetration_tol=penetration_tol)
        gymnasium.Wrapper.__init__(self, env)
        u = env.unwrapped
        model, data = getattr(u, "model", None), getattr(u, "data", None)
        if not isinstance(model, mujoco.MjModel) or not isinstance(data, mujoco.MjData):
            raise InvalidInputError(
                f"SafetyGate needs a MuJoCo env: {type(u).__name__} (env.unwrapped) has no "
                "mujoco.MjModel `model` and mujoco.MjData `data` attributes")
        if not (predictor in ("rollout", "plan") or callable(predictor)):
            raise InvalidInputError(f"predictor must be 'rollout', 'plan' or a callable, got {predictor!r}")
        if predictor == "plan" and not callable(getattr(u, "planned_trajectory", None)):
            raise InvalidInputError(
                f"predictor='plan' needs env.unwrapped.planned_trajectory(action); "
                f"{type(u).__name__} has none")
        if not isinstance(env.action_space, gymnasium.spaces.Box):
            raise InvalidInputError(f"SafetyGate needs a Box action space, got {env.action_space}")
        action_is_ctrl = tuple(env.action_space.shape) == (model.nu,)
        if predictor == "rollout" and not action_is_ctrl:
            raise InvalidInputError(
                f"predictor='rollout' writes the action to data.ctrl, but the action shape "
                f"{env.action_space.shape} is not (nu,) = ({model.nu},); use predictor='plan' or a callable")
        self.predictor_mode = predictor
        self.user_fallback = fallback
        self.timing = bool(timing)
        if fallback is None and not action_is_ctrl:
            # the action is not data.ctrl: "hold position" is unknown, use the zero action
            fallback = np.zeros(env.action_space.shape)
            brake = False  # the braking tail needs the action to be the control
        gate_fallback = None if fallback is None or callable(fallback) else np.asarray(fallback, float)
        self.gate = Gate(model, pairs=pairs, margin=margin, epsilon=epsilon, predictor="rollout",
                         on_violation=on_violation, unsafe=unsafe, budget=budget, log=log,
                         fallback=gate_fallback, brake=brake,
                         frame_skip=int(getattr(u, "frame_skip", 1)), log_options=self._log_options(env),
                         allowed=allowed, hazards=hazards, allow=allow, ongoing=ongoing,
                         penetration_tol=penetration_tol)
        self._obs: Any = None

    def describe(self) -> str:
        """What the gate monitors (pairs, allowed pairs by reason, ongoing-contact rule)."""
        return self.gate.describe()

    # ----------------------------------------------------------------- helpers
    @staticmethod
    def _log_options(env: gymnasium.Env) -> dict[str, Any]:
        """Env id and MJCF source for the log, when the env exposes them."""
        opts: dict[str, Any] = {}
        if env.spec is not None:
            opts["env_id"] = env.spec.id
        src = getattr(env.unwrapped, "fullpath", None)
        if isinstance(src, str):
            opts["model_source"] = src
        return opts

    def _as_action(self, a: Any) -> np.ndarray:
        space = self.env.action_space
        return np.asarray(np.clip(np.asarray(a, dtype=np.float64), space.low, space.high), dtype=space.dtype)

    def _predict_fn(self) -> Callable[[Any], Any] | None:
        u, mode = self.env.unwrapped, self.predictor_mode
        if mode == "rollout":
            return None
        if mode == "plan":
            return u.planned_trajectory
        return lambda a: mode(self.env, self._obs, a)

    def _fallback_fn(self) -> Callable[[], np.ndarray] | None:
        fb = self.user_fallback
        if fb is None:
            return None  # the gate's default: committed brake, else hold position
        if callable(fb):
            return lambda: self._as_action(fb(self.env, self._obs))
        return None  # an array fallback is the gate's own (cast on use)

    # ----------------------------------------------------------------- gymnasium API
    def step(self, action: Any) -> tuple[Any, float, bool, bool, dict[str, Any]]:
        """Certify the window of ``action``, gate it, then step the wrapped env."""
        report: StepReport = self.gate.decide(self.env.unwrapped.data, action, predict=self._predict_fn(),
                                              fallback=self._fallback_fn(), cast=self._as_action)
        obs, reward, terminated, truncated, info = self.env.step(report.applied_ctrl)
        self._obs = obs
        info = dict(info)
        info["safety"] = report.info(timing=self.timing)
        info["cost"] = report.cost  # the applied window's (monitor.gate_policy)
        return obs, reward, bool(terminated or report.terminated), truncated, info

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None
              ) -> tuple[Any, dict[str, Any]]:
        """Reset the wrapped env; ``info["safety"]`` has the same keys with verdict ``""``."""
        obs, info = self.env.reset(seed=seed, options=options)
        self.gate.reset()
        if self.gate._scene is None and self.gate.reference_qpos is None:
            # issue 13: the first reset state is the ACM's reference pose (scene built and announced now)
            self.gate.reference_qpos = np.array(self.env.unwrapped.data.qpos)
        self._obs = obs
        info = dict(info)
        info["safety"] = safety_info(None, verdict="", applied_verdict="", replaced=False,
                                     fallback_certified=True, terminated=False,
                                     time=float(self.env.unwrapped.data.time),
                                     certify_us=0.0 if self.timing else None, npairs=self.gate.npairs)
        info["safety"].update(safety_keys(None))
        info["cost"] = 0.0
        return obs, info

    def close(self) -> None:
        """Close the log (if the gate opened one) and the wrapped env."""
        self.gate.close()
        super().close()


__all__ = ["SafetyGate"]
