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

Wrappers between the gate and the MuJoCo env. The gate predicts the control the
env will actually apply: it walks the chain from the wrapped env down to
``env.unwrapped`` and composes every ``gymnasium.ActionWrapper.action`` transform
(outermost first; e.g. ``RescaleAction``, ``ClipAction``, a user's action wrapper)
into ``T``. Each step evaluates ``c = T(action)`` exactly once; the gate decides in
the env's own action space (for the rollout predictor: ``c`` is the control,
written to the scratch ``ctrl``), then steps the wrapper chain with the action
transforms bypassed for that call, so that ``MujocoEnv.do_simulation`` receives
exactly the certified ``c`` (or the fallback the gate chose instead). Wrappers
known to pass the action through unchanged (``TimeLimit``, ``OrderEnforcing``, ``PassiveEnvChecker``,
``RecordEpisodeStatistics``, observation and reward wrappers, render/record
wrappers, any wrapper that does not override ``step``) are skipped. Any other
wrapper in between (one that overrides ``step``, ``RepeatAction``, ``StickyAction``,
``Autoreset``, ...) could change the motion, and the gate refuses it at
construction (:class:`InvalidInputError` naming the wrapper class). After every
step of the rollout predictor the gate checks that ``data.ctrl`` equals the control
it certified and raises :class:`InvalidInputError` otherwise (e.g. an env whose
``step`` changes the action before ``do_simulation``), so a difference is never
silent. A user fallback (array or callable) is an action of the gate's own action
space and goes through ``T`` like a proposal; the default fallback (hold position)
and the braking-tail check work in the env's control space, as without wrappers.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from typing import Any

import gymnasium
import mujoco
import numpy as np

from monitor.certify.ongoing import DEFAULT_PENETRATION_TOL
from monitor.errors import InvalidInputError
from monitor.gate import Gate, StepReport, safety_info
from monitor.gate_policy import safety_keys
from monitor.gate_settings import fixed_setting

_W = gymnasium.wrappers
_PASS_THROUGH_STEPS = frozenset({
    gymnasium.Wrapper.step, gymnasium.ObservationWrapper.step, gymnasium.RewardWrapper.step,
    _W.TimeLimit.step, _W.OrderEnforcing.step, _W.PassiveEnvChecker.step, _W.RecordEpisodeStatistics.step,
    _W.RecordVideo.step, _W.RenderCollection.step, _W.HumanRendering.step, _W.NormalizeReward.step,
    _W.FrameStackObservation.step, _W.TimeAwareObservation.step,
})
"""``step`` methods that hand the action to the inner env unchanged and step it once."""
_STATEFUL_ACTION_WRAPPERS = (_W.StickyAction,)
"""Action wrappers whose ``action`` depends on more than the action (state, RNG): refused."""
_MISSING = object()


def _identity(action: Any) -> Any:
    return action


def action_wrappers(env: gymnasium.Env) -> list[gymnasium.ActionWrapper]:
    """The action transforms between ``env`` and ``env.unwrapped``, outermost first.

    Args:
        env: the env the gate wraps (it may itself be the unwrapped env).

    Returns:
        the ``ActionWrapper`` instances whose ``action`` maps the gate's action, in the
        order the actions pass through them.

    Raises:
        InvalidInputError: naming the class of a wrapper that could change the action or the
            motion in a way the gate cannot predict.
    """
    chain: list[gymnasium.ActionWrapper] = []
    w, inner = env, env.unwrapped
    while w is not inner:
        cls = type(w)
        if isinstance(w, gymnasium.ActionWrapper) and not isinstance(w, _STATEFUL_ACTION_WRAPPERS) \
                and cls.step is gymnasium.ActionWrapper.step:
            chain.append(w)
        elif not isinstance(w, gymnasium.ActionWrapper) and cls.step in _PASS_THROUGH_STEPS:
            pass
        else:
            raise InvalidInputError(
                f"SafetyGate cannot predict the control through the wrapper "
                f"{cls.__module__}.{cls.__qualname__} between it and the MuJoCo env: it may change the "
                "action or the motion (it overrides step, repeats steps or keeps state). Put SafetyGate "
                "below it, or make it a gymnasium.ActionWrapper whose action() is a function of the action.")
        w = getattr(w, "env", None)
        if w is None:
            raise InvalidInputError(f"env: {cls.__qualname__} has no .env, cannot reach env.unwrapped")
    return chain


def _steps_like_mujoco_env(u: Any) -> bool:
    """True when ``u`` simulates with gymnasium's own ``MujocoEnv._step_mujoco_simulation``.

    That method is ``data.ctrl[:] = ctrl; mj_step(model, data, nstep=n); mj_rnePostConstraint``;
    an env overriding it (or not a ``MujocoEnv``) is never committed into.
    """
    try:
        from gymnasium.envs.mujoco.mujoco_env import MujocoEnv
    except ImportError:  # pragma: no cover - gymnasium without its mujoco envs
        return False
    return (isinstance(u, MujocoEnv)
            and type(u)._step_mujoco_simulation is MujocoEnv._step_mujoco_simulation
            and "_step_mujoco_simulation" not in u.__dict__)


class SafetyGate(gymnasium.Wrapper, gymnasium.utils.RecordConstructorArgs):
    """Certify-then-step wrapper for MuJoCo gymnasium environments.

    Args:
        env: a gymnasium env whose ``unwrapped`` has ``model`` (MjModel) and
            ``data`` (MjData), e.g. any ``MujocoEnv``.
        predictor: ``"rollout"`` (scratch rollout of ``frame_skip`` substeps with
            ``ctrl = action``), ``"plan"`` (``env.unwrapped.planned_trajectory(action)``)
            or a callable ``predictor(env, obs, action) -> Plan``. With action wrappers
            between the gate and the MuJoCo env, ``action`` here is the action the MuJoCo
            env receives (after the wrappers' transforms).
        pairs: candidate pairs (``"mujoco"``, ``"all"`` or geom-name pairs).
        margin: clearance (m) that counts as safe.
        epsilon: certification tolerance (m).
        on_violation: ``"block" | "terminate" | "warn"`` (see :class:`monitor.Gate`).
        fallback: None (hold position where actuators allow, else zeros; the zero
            action, clipped to the action space, when the action is not ``data.ctrl``),
            an action array, or a callable ``fallback(env, obs) -> action``.
        budget: per-step work limit (seconds float, tests int, dict or Budget).
        log: None, an ``.mcap`` path or a :class:`monitor.log.MonitorLog`. A path is claimed
            exclusively (``fcntl.flock``); when another live gate writes it (e.g. the sub-envs
            of ``gym.make_vec(..., wrappers=[partial(SafetyGate, log="x.mcap")])``) this gate
            writes the first free ``x.1.mcap``, ``x.2.mcap``, ... (``gate.log_path``), never
            the same file. A path log is signed when ``$MONITOR_LOG_KEY_FILE`` names a key file
            (:mod:`monitor.log.sign`); a MonitorLog (e.g. ``MonitorLog(path, key=...)``) is not
            recorded in ``env.spec`` (it cannot be copied).
        unsafe: ``"uncertain"`` (default: anything not certified is unsafe) or ``"violation"``.
        timing: add ``info["safety"]["certify_us"]`` (wall time, µs). Off by default
            because a wall time differs between identical runs, which fails
            gymnasium's step-determinism check in ``check_env``; the time is always
            in ``gate.last_report.certify_us`` and ``gate.summary()``.
        brake: recoverability check with a committed brake (see :class:`monitor.Gate`).
        brake_horizon: longest braking tail (s of simulation time, default 0.25): a tail
            shorter than the robot's stopping time leaves it unable to stop before an
            obstacle (docs/notes/session-2026-11-24-late/horizon_sweep.py); see :class:`monitor.Gate`.
        allowed, hazards, allow, ongoing, penetration_tol: pair policy and the
            ongoing-contact rule, see :class:`monitor.Gate` (defaults ``"auto"``, None,
            None, ``"deepen"``, 0.005 m).

    ``predictor_mode``, ``user_fallback`` and ``action_chain`` are fixed (assignment raises
    InvalidInputError); the certification settings are ``gate``'s (:class:`monitor.Gate`: they act
    or raise the same way), except ``gate.frame_skip``: the windows certified are the ones the env
    steps, so set ``env.unwrapped.frame_skip`` (a different ``gate.frame_skip`` raises at the step).

    Raises:
        InvalidInputError: if ``env.unwrapped`` has no MuJoCo model/data, an option is invalid,
            or a wrapper between the gate and the MuJoCo env could change the action in a way
            the gate cannot predict (see the module docstring).
    """

    def __init__(self, env: gymnasium.Env, *, predictor: str | Callable[..., Any] = "rollout",
                 pairs: Any = "mujoco", margin: float = 0.0, epsilon: float = 1e-3,
                 on_violation: str = "block", fallback: Any = None, budget: Any = None, log: Any = None,
                 unsafe: str = "uncertain", timing: bool = False, brake: bool = True,
                 allowed: Any = "auto", hazards: Any = None, allow: Any = None, ongoing: str = "deepen",
                 penetration_tol: float = DEFAULT_PENETRATION_TOL, brake_horizon: float = 0.25) -> None:
        gymnasium.utils.RecordConstructorArgs.__init__(
            self, predictor=predictor, pairs=pairs, margin=margin, epsilon=epsilon,
            on_violation=on_violation, fallback=fallback, budget=budget, unsafe=unsafe,
            log=log if log is None or isinstance(log, str | os.PathLike) else None,  # a MonitorLog: no copy
            timing=timing, brake=brake, allowed=allowed, hazards=hazards, allow=allow, ongoing=ongoing,
            penetration_tol=penetration_tol, brake_horizon=brake_horizon)
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
        self._action_chain = action_wrappers(env)
        self._action_shape = tuple(env.action_space.shape)
        inner_space = u.action_space if self.action_chain else env.action_space
        if not isinstance(inner_space, gymnasium.spaces.Box):
            raise InvalidInputError(f"SafetyGate needs a Box action space in {type(u).__name__}, "
                                    f"got {inner_space}")
        self._inner_space = inner_space
        inner_shape = tuple(inner_space.shape)
        action_is_ctrl = inner_shape == (model.nu,)
        if predictor == "rollout" and not action_is_ctrl:
            raise InvalidInputError(
                f"predictor='rollout' writes the action to data.ctrl, but the action shape "
                f"{inner_shape} is not (nu,) = ({model.nu},); use predictor='plan' or a callable")
        self._predictor_mode, self._user_fallback = predictor, fallback  # fixed (see the properties)
        self.timing = bool(timing)
        gate_fallback = None if callable(fallback) else fallback
        if gate_fallback is not None and self.action_chain:  # an action: the env receives T(fallback)
            gate_fallback = self._inner_action(self.to_ctrl(self._as_action(gate_fallback)), "fallback")
        if fallback is None and not action_is_ctrl:
            # the action is not data.ctrl: "hold position" is unknown, use the zero action
            gate_fallback = self._as_inner(np.zeros(inner_shape))
        if not action_is_ctrl:
            brake = False  # the braking tail needs the action to be the control
        self.gate = Gate(model, pairs=pairs, margin=margin, epsilon=epsilon, predictor="rollout",
                         on_violation=on_violation, unsafe=unsafe, budget=budget, log=log,
                         fallback=gate_fallback, brake=brake,
                         frame_skip=int(getattr(u, "frame_skip", 1)), log_options=self._log_options(env),
                         action_shape=inner_shape, allowed=allowed, hazards=hazards, allow=allow,
                         ongoing=ongoing, penetration_tol=penetration_tol, brake_horizon=brake_horizon)
        if predictor != "rollout":  # the log says whose predictor made the windows (review re-simulates none)
            self.gate._predictor_label = predictor if isinstance(predictor, str) else "callable"
        self._unwrapped = u
        self._gate_frame_skip = self.gate.frame_skip  # the count this wrapper last gave the gate
        self._obs: Any = None
        self._commit_ok = predictor == "rollout" and _steps_like_mujoco_env(u)
        self._expected: tuple[np.ndarray, int, bytes] | None = None  # the certified window (see _commit_sim)
        self.commit = True
        """Commit the gate's own integration of the applied window instead of simulating it
        again when the env steps (see :meth:`_commit_sim`); False: the env always simulates.
        Set it False for an env whose ``step`` edits the model's dynamics (masses, gains,
        friction) after the gate decided and before it simulates: the scratch window was
        integrated with the model as it was at the decision, and the commit compares the
        integration state and control, not the model."""

    action_chain = fixed_setting("action_chain", "the action wrappers between the gate and the MuJoCo env, "
                                                 "found at construction", arg="env")
    predictor_mode = fixed_setting("predictor_mode", "the predictor; the commit hook and the brake check "
                                                     "were chosen for it", arg="predictor")
    user_fallback = fixed_setting("user_fallback", "the fallback; an action array was converted into the "
                                                   "gate's fallback at construction", arg="fallback")

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
        """A gate-made or fallback action, clipped to the action space and cast to its dtype."""
        space = self.env.action_space
        try:
            arr = np.asarray(a, dtype=np.float64)
        except (TypeError, ValueError) as e:
            raise InvalidInputError(f"fallback must give a numeric action, got {a!r}") from e
        if arr.shape not in ((), self._action_shape) or not np.isfinite(arr).all():
            raise InvalidInputError(f"fallback must give a finite action of shape {self._action_shape}, "
                                    f"got {arr!r}")
        return np.asarray(np.clip(arr, space.low, space.high), dtype=space.dtype)

    def _as_inner(self, a: Any) -> np.ndarray:
        """A gate-made action of the env's own action space (hold, brake), clipped to it and cast."""
        space = self._inner_space
        # ndarray.clip: what np.clip calls for an ndarray, without its dispatch (same values)
        return np.asarray(np.asarray(a, dtype=np.float64).clip(space.low, space.high), dtype=space.dtype)

    def _inner_action(self, c: Any, what: str) -> np.ndarray:
        """``c = T(action)`` checked: a finite numeric array of the env's own action shape."""
        shape = tuple(self._inner_space.shape)
        try:
            arr = np.asarray(c)
            ok = arr.shape == shape and np.isfinite(np.asarray(arr, dtype=np.float64)).all()
        except (TypeError, ValueError):
            ok = False
        if not ok:
            raise InvalidInputError(f"{what}: the action wrappers map it to {c!r}, not a finite array of "
                                    f"shape {shape} for {type(self.env.unwrapped).__name__}")
        return arr

    def to_ctrl(self, action: Any) -> Any:
        """The action as the MuJoCo env receives it: every action wrapper's ``action()``, outermost first."""
        for w in self.action_chain:
            action = w.action(action)
        return action

    def _step_env(self, inner_action: Any) -> tuple[Any, float, bool, bool, dict[str, Any]]:
        """Step the wrapped env so that the MuJoCo env receives exactly ``inner_action``.

        The action wrappers' transforms were applied by the gate already (once); for this
        call each ``ActionWrapper.action`` is the identity. Every other wrapper steps as usual.
        """
        if not self.action_chain:
            return self.env.step(inner_action)
        saved = [w.__dict__.get("action", _MISSING) for w in self.action_chain]
        for w in self.action_chain:
            w.action = _identity  # instance attribute: shadows the class's transform for this call
        try:
            return self.env.step(inner_action)
        finally:
            for w, old in zip(self.action_chain, saved):
                if old is _MISSING:
                    del w.action
                else:
                    w.action = old

    def _predict_fn(self) -> Callable[[Any], Any] | None:
        mode = self.predictor_mode
        if mode == "rollout":
            return None  # the gate's own rollout with ctrl = the env's action
        u = self.env.unwrapped
        if mode == "plan":
            return u.planned_trajectory
        return lambda a: mode(self.env, self._obs, a)

    def _commit_sim(self, ctrl: Any, n_frames: int) -> None:
        """``MujocoEnv._step_mujoco_simulation`` that reuses the gate's scratch window when it is exact.

        The gate's rollout integrated ``n_frames`` substeps under the certified control from a
        full copy of the env's ``MjData`` (:meth:`monitor.gate.Rollout.states`). When the env's
        data still has exactly that integration state and ``ctrl`` is exactly that control
        (both compared bit for bit by :meth:`monitor.gate.Rollout.commit`), the scratch's end
        state is copied into the env's data instead of stepping again: the same result as
        ``data.ctrl[:] = ctrl; mj_step(model, data, nstep=n_frames)`` (``mj_step`` is a
        deterministic function of the integration state; tested field by field against an
        ungated env). Then ``mj_rnePostConstraint`` as gymnasium does. Anything else (a
        window inside the committed braking tail, a changed state, another control or
        ``n_frames``): gymnasium's own simulation.
        """
        u = self._unwrapped
        self._check_geometry("nothing was simulated")  # refused BEFORE the motion runs
        if u.model is self.gate.model and self.gate._rollout.commit(u.data, ctrl, int(n_frames)):
            mujoco.mj_rnePostConstraint(u.model, u.data)
            self.gate.stats["committed"] += 1
        else:
            why = self._uncertified_simulation(ctrl, int(n_frames))
            if why:  # refused BEFORE the motion runs
                raise InvalidInputError(
                    f"env: {type(u).__name__}.step is about to simulate a window the gate did not certify: "
                    f"{why}; nothing was simulated")
            type(u)._step_mujoco_simulation(u, ctrl, n_frames)
        self._expected = None  # one window per step: a second simulation in the same step is refused

    def _uncertified_simulation(self, ctrl: Any, n_frames: int) -> str:
        """Why the simulation about to run (hooked ``_step_mujoco_simulation``) is not the certified window.

        Empty when nothing identifiable differs (the env then simulates as gymnasium does).
        """
        exp = self._expected
        if exp is None:
            return "a second simulation in one env step (do_simulation called again)"
        applied, nstep, mocap_start = exp
        d = self._unwrapped.data
        c = np.asarray(ctrl, dtype=np.float64)
        if c.shape != applied.shape or c.tobytes() != applied.tobytes():
            return (f"ctrl {np.array2string(c)} instead of the certified ctrl {np.array2string(applied)}")
        if n_frames != nstep:
            return f"{n_frames} substeps instead of the certified {nstep} (frame_skip)"
        if d.mocap_pos.tobytes() + d.mocap_quat.tobytes() != mocap_start:
            return "a mocap body was moved (data.mocap_pos/mocap_quat) after the gate decided"
        if self._unwrapped.model is not self.gate.model:
            return "env.unwrapped.model is not the model the gate certified against"
        return "the simulator state (time, qpos, qvel, act, ...) was changed after the gate decided"

    def _check_geometry(self, outcome: str) -> None:
        """Raise if a watched model array (``scene.SYNC_FIELDS``) was edited since the gate decided.

        :meth:`Gate.decide` re-read the model into the scene (``Scene.sync``); an edit between
        then and the simulation (e.g. an obstacle's ``geom_pos``/``body_pos`` moved inside the
        env's ``step``) runs the motion against geometry the gate never certified.
        """
        snap = getattr(self.gate._scene, "_snapshot", None)
        if snap is None or snap.unchanged():
            return
        raise InvalidInputError(
            f"env: {type(self._unwrapped).__name__}.step edited the model's geometry or kinematics "
            f"({', '.join(snap.changed())}) after the gate certified the window on the model as it was: "
            f"{outcome} (edit the model before calling step: the gate re-reads it every step)")

    def _check_applied_ctrl(self, applied: Any) -> None:
        """Raise if the control the env wrote is not the one the gate certified (rollout predictor)."""
        if self.predictor_mode != "rollout":
            return
        expected = np.asarray(applied, dtype=np.float64)
        ctrl = self._unwrapped.data.ctrl
        # equal shapes (1-D: data.ctrl is (nu,)): the lists of Python floats compare element by element
        # with float ==, as (ctrl == expected).all() does (NaN unequal, -0.0 == 0.0), in one C call
        if ctrl.shape != expected.shape or ctrl.tolist() != expected.tolist():
            raise InvalidInputError(
                f"env: after the step data.ctrl = {np.array2string(ctrl)} but the gate certified ctrl = "
                f"{np.array2string(expected)}: something between SafetyGate and "
                f"{type(self.env.unwrapped).__name__}, or its step, changed the action in a way the gate "
                "cannot predict; the window that ran was not certified")

    def _live_frame_skip(self) -> int:
        """The env's ``frame_skip`` as it is now (read every step; a user may change it after construction).

        The gate certifies windows of this many substeps: a count read once at construction
        would certify a shorter window than the env then simulates.

        Raises:
            InvalidInputError: ``env.unwrapped.frame_skip`` is not an integer >= 1.
        """
        fs = getattr(self._unwrapped, "frame_skip", 1)
        if isinstance(fs, (bool, np.bool_)) or not isinstance(fs, (int, np.integer)) or fs < 1:
            raise InvalidInputError(f"env.unwrapped.frame_skip must be an integer >= 1, got {fs!r}")
        fs = int(fs)
        gate_fs = self.gate.frame_skip
        if gate_fs != self._gate_frame_skip and gate_fs != fs:  # the user's gate.frame_skip cannot act here
            raise InvalidInputError(
                f"SafetyGate.gate.frame_skip was set to {gate_fs!r}, but the gate certifies the windows the "
                f"env steps: env.unwrapped.frame_skip ({fs}) substeps; set env.unwrapped.frame_skip instead")
        if fs != gate_fs:
            self.gate.frame_skip = self._gate_frame_skip = fs
        return fs

    def _check_elapsed(self, t_start: float, nstep: int) -> None:
        """Raise if the env simulated past the certified window's end (rollout predictor).

        ``mj_step`` advances ``data.time`` by ``opt.timestep`` per substep; the same float
        additions from the window's start time give the certified window's end time. An env
        whose ``step`` simulates more substeps (``do_simulation`` called twice, an extra
        ``mj_step``, another count than ``frame_skip``) ran a motion the gate did not
        certify: never silently. Fewer substeps under the certified control are a prefix of
        the certified window (an env simulating its own way, or not at all, is not refused).
        """
        if self.predictor_mode != "rollout":
            return
        dt = self._unwrapped.model.opt.timestep
        t_end = t_start
        for _ in range(nstep):
            t_end += dt
        t_now = float(self._unwrapped.data.time)
        if t_now > t_end:
            raise InvalidInputError(
                f"env: the step advanced data.time from {t_start!r} to {t_now!r} s, but the gate certified "
                f"{nstep} substep(s) of {dt!r} s (to {t_end!r} s): {type(self._unwrapped).__name__}.step "
                "simulated another motion than the certified window (e.g. do_simulation called twice or "
                "with another count than frame_skip); the extra motion was not certified")

    def _check_window_ran(self, applied: Any, nstep: int, mocap_start: bytes, committed: bool) -> None:
        """Raise if the motion the env ran is not the certified window (rollout predictor).

        * Mocap poses: the window's plan holds them at their values when the gate decided; an
          env whose ``step`` moves a mocap body (an obstacle, a mocap-driven gripper) before
          it simulates ran against geometry the gate never saw.
        * When the env simulated itself (not committed from the gate's scratch): ``data.qpos``
          must be the certified window's row at ``data.time`` bit for bit (MuJoCo is
          deterministic: the same state, control and model give the same rows); a ``step``
          that edits the model's dynamics, ``data.eq_active``, ``qfrc_applied`` or the state
          before simulating, or changes ``qpos`` after it, ran another motion.
        * When committed: ``data.qpos`` must still be the window's last row (a ``step`` that moves
          the state after the simulation, e.g. a teleport, ran a motion the window does not hold).

        Raises:
            InvalidInputError: naming what differed; the motion that ran was not certified.
        """
        if self.predictor_mode != "rollout":
            return
        d = self._unwrapped.data
        if d.mocap_pos.tobytes() + d.mocap_quat.tobytes() != mocap_start:
            raise InvalidInputError(
                f"env: {type(self._unwrapped).__name__}.step moved a mocap body (data.mocap_pos/mocap_quat) "
                "after the gate certified the window with the mocap poses as they were: the motion that "
                "ran was not certified (move mocap bodies before calling step, or use predictor='plan' "
                "with a plan that carries them)")
        ro = self.gate._rollout
        if committed:
            # the scratch's end state was copied in: a qpos other than the window's last row was set by
            # the env's step after the simulation (a teleport the window never certified; red team 10)
            rows = ro.window_rows
            if rows is not None and d.qpos.tobytes() != rows[-1, 1:].tobytes():
                raise InvalidInputError(
                    f"env: after the step data.qpos = {np.array2string(d.qpos)} but the certified window "
                    f"ends at {np.array2string(rows[-1, 1:])}: {type(self._unwrapped).__name__}.step moved "
                    "the state after the simulation; that motion was not certified")
            return
        rows = ro.window_rows
        c = np.asarray(applied, dtype=np.float64)
        if rows is None or len(rows) != nstep + 1 or c.tobytes() != ro._key_ctrl_bytes:
            return  # the scratch does not hold the applied window (not the gate's own rollout)
        hits = np.flatnonzero(rows[1:, 0] == d.time)
        if len(hits) != 1:
            if d.time == rows[0, 0]:
                return  # no substep ran (fewer substeps under the same timestep: a row, a prefix)
            raise InvalidInputError(
                f"env: after the step data.time = {d.time!r} s is not a substep time of the certified window "
                f"(from {float(rows[0, 0])!r} s, {nstep} substep(s) to {float(rows[-1, 0])!r} s): "
                f"{type(self._unwrapped).__name__}.step simulated another motion (opt.timestep or the time "
                "edited inside step?); the motion that ran was not certified")
        row = rows[1 + int(hits[0]), 1:]
        if row.tobytes() != d.qpos.tobytes():
            raise InvalidInputError(
                f"env: after the step data.qpos = {np.array2string(d.qpos)} but the certified window has "
                f"{np.array2string(row)} at t = {d.time!r} s: {type(self._unwrapped).__name__}.step "
                "simulated another motion than the certified one (model or state edited inside step?); "
                "the motion that ran was not certified")

    def _fallback_fn(self) -> Callable[[], np.ndarray] | None:
        fb = self.user_fallback
        if fb is None:
            return None  # the gate's default: committed brake, else hold position
        if callable(fb):
            if not self.action_chain:
                return lambda: self._as_action(fb(self.env, self._obs))
            return lambda: self._inner_action(self.to_ctrl(self._as_action(fb(self.env, self._obs))),
                                              "fallback")
        return None  # an array fallback is the gate's own (cast on use)

    # ----------------------------------------------------------------- gymnasium API
    def step(self, action: Any) -> tuple[Any, float, bool, bool, dict[str, Any]]:
        """Certify the window of ``action``, gate it, then step the wrapped env.

        Raises:
            InvalidInputError: ``action`` is not a finite numeric array of the action space's
                shape, or (rollout predictor) the env applied a control other than the certified one.
        """
        shape = self._action_shape
        try:
            arr = np.asarray(action, dtype=np.float64)
        except (TypeError, ValueError) as e:
            raise InvalidInputError(f"action must be a numeric array of shape {shape}, got {action!r}") from e
        if arr.shape != shape:
            raise InvalidInputError(f"action must have shape {shape} (the action space's), got {arr.shape}")
        if not np.isfinite(arr).all():
            raise InvalidInputError(f"action contains NaN or inf: {arr}")
        if self.action_chain:
            action = self._inner_action(self.to_ctrl(action), "action")  # T evaluated once per step
        u = self._unwrapped
        if u.model is not self.gate.model:
            raise InvalidInputError(
                f"env: {type(u).__name__}.model is not the MjModel the gate was built on (the env replaced "
                "it, e.g. recompiled a spec at reset): the gate would certify against the old model; "
                "edit the model in place (the gate re-reads it) or build a new SafetyGate")
        nstep = self._live_frame_skip()
        t_start = float(u.data.time)
        mocap_start = u.data.mocap_pos.tobytes() + u.data.mocap_quat.tobytes()  # held over the window
        committed_before = self.gate.stats["committed"]
        report: StepReport = self.gate.decide(u.data, action, nstep=nstep, predict=self._predict_fn(),
                                              fallback=self._fallback_fn(), cast=self._as_inner)
        hook = self._commit_ok and self.commit and "_step_mujoco_simulation" not in u.__dict__
        # the env steps its own copy: a step that edits the action array in place (action *= k) must
        # not edit the certified control the checks below compare with (red team 10)
        certified = np.asarray(report.applied_ctrl, dtype=np.float64)
        if hook:  # instance attribute: shadows MujocoEnv._step_mujoco_simulation for this call only
            u._step_mujoco_simulation = self._commit_sim
            self._expected = (certified, nstep, mocap_start)
        try:
            obs, reward, terminated, truncated, info = self._step_env(np.array(report.applied_ctrl))
        finally:
            if hook:
                del u._step_mujoco_simulation
        if not (hook and self._expected is None):  # the hook did not run (it checks before simulating)
            self._check_geometry("the motion that ran was not certified")
        self._check_applied_ctrl(certified)
        self._check_elapsed(t_start, nstep)
        self._check_window_ran(certified, nstep, mocap_start,
                               self.gate.stats["committed"] != committed_before)
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
        if self.gate._scene_builds == 0 and self.gate.reference_qpos is None:
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


SafetyGate._as_inner._model_untouched = True  # type: ignore[attr-defined]  # decide's `cast`: no model edit

__all__ = ["SafetyGate"]
