"""Plain-MuJoCo safety gate: certify the next window of motion, then step or block.

:class:`Gate` is the gymnasium-free core. It turns (state, control) into a
:class:`monitor.Plan` for the upcoming window (the *predictor*), certifies it
with :func:`monitor.certify`, and applies a gating policy:

* ``"block"``: an unsafe control is replaced by the fallback (default: hold the
  current position where the actuators allow it, else zero). The fallback's
  own window is certified too; if it fails, the report says so
  (``fallback_certified=False``), the window is logged and a warning is logged.
* ``"terminate"``: like ``"block"`` (the unsafe control is never applied), and
  the report asks the caller to end the episode (``terminated=True``).
* ``"warn"``: the control is applied anyway and the verdict recorded.

What counts as unsafe: with ``unsafe="uncertain"`` (default) anything that is
not ``"certified"``; with ``unsafe="violation"`` only a confirmed violation.

Rollout predictor. The full integration state (``mjSTATE_INTEGRATION``: time,
qpos, qvel, act, warm start, ctrl, mocap, ...) of the caller's ``MjData`` is
copied into a private scratch ``MjData``; the control is written to
``scratch.ctrl`` (exactly what gymnasium's ``MujocoEnv.do_simulation`` does)
and ``nstep`` substeps are integrated, recording qpos after each. The plan
interpolates between consecutive simulator states, so a body that jumps over a
thin wall between two substeps (tunnelling, invisible to MuJoCo's discrete
contacts) is seen by the certifier. The caller's ``MjData`` is never written
while predicting.

Certificate reuse. Pairs whose two bodies do not move in the window and whose
poses equal those of an earlier certified window are not re-certified; only
the other pairs go to :func:`monitor.certify` (its ``pairs=`` argument). The
reused results are exact: a pair of fixed bodies at identical poses has the
same clearance. The cache is keyed on everything a pair result depends on:
the two bodies' poses, ``margin``, ``epsilon``, ``tolerances`` and the scene's
geometry version (``Scene.version``, bumped by ``Scene.sync()`` when the live
model was edited; the gate syncs before every window). Changing any of these
empties the cache.

Logs. ``log="x.mcap"`` claims the path with an exclusive ``fcntl.flock`` for as
long as the gate writes it. A path already claimed by another live gate (in
this or another process, e.g. the sub-envs of a vector env built with one
``log=`` argument) is never overwritten: the gate writes ``x.1.mcap``,
``x.2.mcap``, ... instead (the first free one; see :attr:`Gate.log_path`). Every window
whose rows come from this rollout is logged with the integration state it started from and
its substep controls (:mod:`monitor.log.replay`; ``review --verify`` re-simulates it), and
in-place model edits are noted before every window (dynamics too: a few µs per window).

This module imports mujoco and monitor only (no gymnasium, no mcap).
"""

from __future__ import annotations

import logging
import math
import os
import time
import warnings
import weakref
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import mujoco
import numpy as np

from monitor.certify.certificate import Certificate, PairResult, combine_verdicts, nothing_checked_stats
from monitor.certify.ongoing import DEFAULT_PENETRATION_TOL, check_rule
from monitor.certify.request import BudgetLimits, CertifyRequest
from monitor.certify.types import Method, Verdict
from monitor.errors import InvalidInputError
from monitor.gate_policy import announce, applied_cost, block_reason, describe_gate, safety_keys
from monitor.gate_settings import (
    check_choice,
    check_flag,
    check_reference,
    checked_setting,
    fixed_setting,
    frozen_items,
)
from monitor.tolerances import DEFAULT, Tolerances

_LOG = logging.getLogger("monitor.gate")

ON_VIOLATION = ("block", "terminate", "warn")
UNSAFE = ("uncertain", "violation")
PREDICTORS = ("rollout",)
_INTEGRATION = mujoco.mjtState.mjSTATE_INTEGRATION
_TAIL_ROW = (mujoco.mjtState.mjSTATE_TIME | mujoco.mjtState.mjSTATE_QPOS
             | mujoco.mjtState.mjSTATE_QVEL)  # state layout: time, qpos (nq), qvel (nv)
_WINDOW_ROW = mujoco.mjtState.mjSTATE_TIME | mujoco.mjtState.mjSTATE_QPOS  # time, qpos (nq)
_UNSTABLE = slice(int(mujoco.mjtWarning.mjWARN_BADQPOS), int(mujoco.mjtWarning.mjWARN_BADQACC) + 1)
"""MuJoCo warnings of an unstable simulation (NaN, Inf or huge qpos/qvel/qacc; MuJoCo resets the state)."""
assert (_UNSTABLE.stop - _UNSTABLE.start == 3
        and int(mujoco.mjtWarning.mjWARN_BADQVEL) == _UNSTABLE.start + 1)  # BADQPOS, BADQVEL, BADQACC


def _unstable_counts(d: mujoco.MjData) -> np.ndarray:
    """A live view of ``d``'s warning counters BADQPOS, BADQVEL, BADQACC (3,) int."""
    return d.warning.number[_UNSTABLE]
_TAIL_CHUNK = 32  # longest run of braking-tail substeps between two (vectorised) stop tests


# --------------------------------------------------------------------------- predictors
class Rollout:
    """Exact one-window prediction by integrating a scratch copy of the state.

    Cost. Per window everything is preallocated or cached: the integration-state
    buffers, the views of the scratch ``MjData`` arrays read per substep, and a
    second scratch ``MjData`` for the braking tail. After :meth:`states` the window
    scratch holds the complete ``MjData`` at the window's end, together with the key
    it was computed from (the caller's integration state, the control, ``nstep``):

    * :meth:`brake_tail` continues from that snapshot instead of integrating the
      window a second time, when the key matches;
    * :meth:`commit` copies it into the caller's ``MjData`` instead of stepping it
      again (used by :meth:`Gate.step`), when the key matches.

    Both are exact, not approximations: ``mj_step`` is a deterministic function of
    the integration state (``mjSTATE_INTEGRATION``: time, qpos, qvel, act, warm
    start, ctrl, applied forces, mocap, eq_active, userdata, plugin state,
    history), so the scratch's end state is bit for bit what ``mj_step`` on the
    caller's data would produce (tested against an independent ``MjData`` on every
    array field over 500 tunnel steps). The key is compared bit for bit. The model
    is the one object both run on; an in-place model edit between a prediction and
    its commit is not detected here (:meth:`Gate.step` predicts and commits within
    one call, with only the certifier in between, which does not edit the model).

    Args:
        model: the ``MjModel``.
    """

    def __init__(self, model: mujoco.MjModel) -> None:
        self.model = model
        self.scratch = mujoco.MjData(model)
        self._tail_data: mujoco.MjData | None = None  # created on the first braking tail
        size = mujoco.mj_stateSize(model, _INTEGRATION)
        self._state = np.empty(size)
        self._key_state = np.empty(size)  # integration state the scratch window started from
        self._end_state = np.empty(size)
        self._key_ctrl = np.empty(model.nu)
        self._key_state_bytes = self._key_ctrl_bytes = b""  # bytes of _key_state / _key_ctrl (the key)
        self._key_nstep = 0  # 0: the scratch holds no complete window
        self.window_rows: np.ndarray | None = None
        """(nstep + 1, 1 + nq) rows (time, qpos) of the last :meth:`states` call, or None."""
        self.window_key: tuple[bytes, bytes, int] | None = None
        """(integration state at the start, ctrl (nu,), nstep) of :attr:`window_rows`: raw float64 bytes
        (fresh per window, never overwritten), from which the rows re-simulate bit for bit (a log's
        ``rollout``; see :func:`_logged_rollout`)."""
        self._s_ctrl = self.scratch.ctrl  # a view (an MjData's buffers never move)
        self._s_warn = _unstable_counts(self.scratch)  # a view too: the unstable-simulation counters
        self.c_tail = True
        """Run braking tails in ``mujoco.rollout`` where exact (False: always the ``mj_step`` loop)."""
        self._roll: Any = None  # mujoco._rollout.Rollout, created on the first C tail
        self._tail_bufs: tuple[np.ndarray, ...] | None = None  # buffers of the C tail (see _tail_by_rollout)
        self._n_full = self._n_user = 0
        self.tails = 0
        """Braking tails simulated by :meth:`brake_rows` (a measure of the gate's physics cost)."""
        self.tail_substeps = 0
        """Substeps simulated in those tails (each ends at rest, ``vel_tol``, or at ``max_steps``)."""

    def __getstate__(self) -> dict[str, Any]:
        """Pickle / deepcopy state: without the C rollout object and views into the scratches.

        ``mujoco._rollout.Rollout`` does not pickle, and a copied view of a scratch array
        (``_s_ctrl``, the tail's warning counters and warm start) would be a detached copy,
        no longer the copied ``MjData``'s memory; all are rebuilt from the copied scratches.
        """
        state = self.__dict__.copy()
        state.pop("_s_ctrl", None)
        state.pop("_s_warn", None)
        state["_roll"] = None
        state["_tail_bufs"] = None
        return state

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.__dict__.update(state)
        self._s_ctrl = self.scratch.ctrl
        self._s_warn = _unstable_counts(self.scratch)

    def window_matches(self, data: mujoco.MjData, ctrl: np.ndarray | None, nstep: int) -> bool:
        """True when the scratch holds the end of ``nstep`` substeps of ``data`` under ``ctrl``.

        Compares ``data``'s integration state and the control with the last :meth:`states`
        call bit for bit (``ctrl=None``: ``data.ctrl``): their bytes, so ``-0.0`` and ``0.0``
        differ and a NaN equals only the same NaN (a stricter test than ``np.array_equal``;
        a state that fails it is simulated again, never committed).
        """
        if nstep < 1 or self._key_nstep != nstep:
            return False
        c = data.ctrl if ctrl is None else ctrl
        if type(c) is not np.ndarray or c.dtype != np.float64:
            c = np.asarray(c, dtype=np.float64)
        if c.shape != self._key_ctrl.shape or c.tobytes() != self._key_ctrl_bytes:
            return False
        mujoco.mj_getState(self.model, data, self._state, _INTEGRATION)
        return self._state.tobytes() == self._key_state_bytes

    def states(self, data: mujoco.MjData, ctrl: np.ndarray | None, nstep: int
               ) -> tuple[np.ndarray, np.ndarray]:
        """Simulator states of the next ``nstep`` substeps, without touching ``data``.

        Args:
            data: the live ``MjData`` (read only).
            ctrl: (nu,) control held over the window, or None to keep ``data.ctrl``.
            nstep: number of ``mj_step`` substeps (>= 1).

        Returns:
            times (nstep + 1,) seconds and qpos (nstep + 1, nq): the current state
            (quaternions normalised, as MuJoCo uses them) followed by the state
            after each substep. Fresh arrays: the caller may keep them.
        """
        rows = self._window(data, ctrl, nstep)
        return rows[:, 0].copy(), rows[:, 1:].copy()

    def _window(self, data: mujoco.MjData, ctrl: np.ndarray | None, nstep: int) -> np.ndarray:
        """:meth:`states` as one read-only array ``rows`` (nstep + 1, 1 + nq) of (time, qpos).

        ``rows[:, 0]`` and ``rows[:, 1:]`` are exactly :meth:`states`' times and qpos (row 0's
        quaternions normalised); also kept as :attr:`window_rows`.
        """
        m, s = self.model, self.scratch
        self._key_nstep = 0  # no complete window until the loop below is done
        key = self._key_state
        mujoco.mj_getState(m, data, key, _INTEGRATION)
        # A full copy, not only the integration state: then the scratch also carries
        # data's diagnostics (warning counters, solver statistics, fields a substep
        # does not rewrite), so :meth:`commit` gives exactly what stepping data gives.
        mujoco.mj_copyData(s, m, data)
        if ctrl is not None:
            self._s_ctrl[:] = ctrl
        self._key_ctrl[:] = self._s_ctrl
        self._key_ctrl_bytes = self._key_ctrl.tobytes()
        self._key_state_bytes = key.tobytes()
        ncol = 1 + m.nq
        rows = np.empty((nstep + 1, ncol))  # (time, qpos) per state, by mj_getState
        # The integration state begins with time, qpos (mj_getState writes its parts in
        # mjtState bit order: TIME, QPOS, QVEL, ...): row 0 is its first 1 + nq entries.
        rows[0] = key[:ncol]
        warn = self._s_warn
        unstable = warn.tobytes()
        step, get_state = mujoco.mj_step, mujoco.mj_getState  # (read once per window, not per substep)
        for k in range(1, nstep + 1):
            step(m, s)
            get_state(m, s, rows[k], _WINDOW_ROW)
        if warn.tobytes() != unstable:
            raise InvalidInputError(
                f"the predicted window from t = {float(rows[0, 0])!r} s ({nstep} substep(s) under ctrl = "
                f"{np.array2string(self._key_ctrl)}) is an unstable simulation (MuJoCo: NaN, Inf or huge "
                "qpos/qvel/qacc; it resets the state): no motion to certify. Lower opt.timestep, use an "
                "implicit integrator, or check the control and the model's gains")
        self._key_nstep = int(nstep)
        self.window_key = (self._key_state_bytes, self._key_ctrl_bytes, self._key_nstep)
        # MuJoCo normalises free/ball quaternions when it uses them (kinematics,
        # integration); a state set by hand (e.g. a noisy reset) may not be.
        mujoco.mj_normalizeQuat(m, rows[0, 1:])  # in place (a contiguous row)
        rows.setflags(write=False)  # shared by the window's rows object, the joint call and the tail
        self.window_rows = rows  # (time, qpos) rows exactly as returned (the Plan normalises its copy)
        return rows

    def commit(self, data: mujoco.MjData, ctrl: np.ndarray | None, nstep: int) -> bool:
        """Advance ``data`` by the predicted window if the scratch holds it (else do nothing).

        Same result as ``data.ctrl[:] = ctrl; mj_step(model, data, nstep=nstep)``: the
        scratch started as a full copy of ``data`` (``mj_copyData``, diagnostics included)
        and ran exactly those substeps, and it is copied back. Bit for bit in every array
        of ``MjData``, the warning counters, solver statistics and memory high-water marks
        (tested); the wall-clock ``timer`` durations are the scratch run's.

        Returns:
            True if ``data`` was advanced; False if the scratch does not hold this window
            (the caller steps ``data`` itself).
        """
        if not self.window_matches(data, ctrl, nstep):
            return False
        mujoco.mj_copyData(data, self.model, self.scratch)
        self._key_nstep = 0  # used up: data has moved on
        return True

    def plan(self, data: mujoco.MjData, ctrl: np.ndarray | None, nstep: int) -> Any:
        """The :class:`monitor.Plan` of the next ``nstep`` substeps (mocap poses held)."""
        from monitor.motion.plan import Plan

        times, qpos = self.states(data, ctrl, nstep)
        return Plan._trusted(times, qpos, model=self.model, mocap_pos=np.array(data.mocap_pos),
                             mocap_quat=np.array(data.mocap_quat))

    def brake_tail(self, data: mujoco.MjData, ctrl: np.ndarray, nstep: int,
                   brake_fn: Callable[[mujoco.MjData], np.ndarray], max_steps: int,
                   vel_tol: float) -> tuple[Any, np.ndarray, np.ndarray]:
        """Plan of the braking motion that would follow the window of ``ctrl``.

        Integrates the window (``nstep`` substeps under ``ctrl``), then holds the
        brake control ``brake_fn(state at the window's end)`` until every
        ``|qvel| <= vel_tol`` or ``max_steps`` substeps.

        The window is not integrated again when the scratch already holds it (the
        gate predicted it just before): the tail starts from the scratch's end state
        (``mj_setState`` of its integration state into a second scratch ``MjData``,
        which determines every later ``mj_step`` bit for bit). ``brake_fn`` receives
        that ``MjData``: its integration state (qpos, qvel, act, ctrl, ...) is the
        window's end; quantities derived from it (``xpos``, contacts, ...) are not
        recomputed (the gate's brake functions read ``qpos`` only).

        Returns:
            (plan of the tail from the window's end, brake control (nu,),
            qvel (K, nv) at the tail's waypoints).
        """
        from monitor.motion.plan import Plan

        rows, brake = self.brake_rows(data, ctrl, nstep, brake_fn, max_steps, vel_tol)
        nq = self.model.nq
        plan = Plan._trusted(rows[:, 0].copy(), rows[:, 1:1 + nq].copy(), model=self.model,
                             mocap_pos=np.array(data.mocap_pos), mocap_quat=np.array(data.mocap_quat))
        return plan, brake, rows[:, 1 + nq:].copy()

    def brake_rows(self, data: mujoco.MjData, ctrl: np.ndarray, nstep: int,
                   brake_fn: Callable[[mujoco.MjData], np.ndarray], max_steps: int,
                   vel_tol: float, *, window_fresh: bool = False) -> tuple[np.ndarray, np.ndarray]:
        """The braking tail of :meth:`brake_tail` as raw rows, without building its Plan.

        ``window_fresh=True`` is the caller's promise that :meth:`states` just ran on this
        ``data``, ``ctrl`` and ``nstep`` (the gate's order): the key check is skipped.

        The substeps run in MuJoCo's C rollout (``mujoco.rollout``, no Python per substep)
        where that is provably the same computation as the ``mj_step`` loop
        (:meth:`_tail_by_rollout`), else in the loop (:meth:`_tail_by_loop`). Same rows,
        same stop index, bit for bit (tested against an independent hand-stepped oracle).

        Returns:
            rows (K, 1 + nq + nv): time, qpos, qvel at the tail's waypoints (the first is the
            window's end), and the brake control (nu,).
        """
        m = self.model
        if not (window_fresh and self._key_nstep == nstep) and not self.window_matches(data, ctrl, nstep):
            self._window(data, ctrl, nstep)
        s = self._tail_data
        if s is None:
            s = self._tail_data = mujoco.MjData(m)
        mujoco.mj_getState(m, self.scratch, self._end_state, _INTEGRATION)
        mujoco.mj_setState(m, s, self._end_state, _INTEGRATION)
        brake = np.asarray(brake_fn(s), dtype=np.float64)
        s.ctrl[:] = brake
        n = max(int(max_steps), 1)
        if self.c_tail and _rollout_is_exact(m):
            rows = self._tail_by_rollout(n, vel_tol)
            if rows is not None:
                self.tails += 1
                self.tail_substeps += len(rows) - 1
                return rows, brake
            # a MuJoCo warning in the tail: redo it in the loop (the rollout stops stepping there)
            mujoco.mj_setState(m, s, self._end_state, _INTEGRATION)
            s.ctrl[:] = brake
        warn = _unstable_counts(s)
        warn[:] = 0  # the private tail scratch (never committed): MuJoCo's reset keeps only the new count
        rows = self._tail_by_loop(n, vel_tol)
        if warn.any() and not (np.isfinite(rows).all() and (np.diff(rows[:, 0]) > 0).all()):
            self.tail_unstable = True  # rows as MuJoCo gives them (reset included); the gate refuses them
        self.tails += 1
        self.tail_substeps += len(rows) - 1
        return rows, brake

    tail_unstable = False
    """True after :meth:`brake_rows` gave the rows of an unstable simulation (MuJoCo reset the state)."""

    def check_tail(self) -> None:
        """Raise (and clear the flag) if the last braking tail was an unstable simulation."""
        if self.tail_unstable:
            self.tail_unstable = False
            raise InvalidInputError(
                "the braking tail after the window is an unstable simulation (MuJoCo: NaN, Inf or huge "
                "qpos/qvel/qacc; it resets the state): no motion to certify. Lower opt.timestep, use an "
                "implicit integrator, or check the model's gains")

    def _tail_by_loop(self, n: int, vel_tol: float) -> np.ndarray:
        """Up to ``n`` substeps of the tail scratch (state and brake control set), one ``mj_step`` each.

        Returns:
            rows (K, 1 + nq + nv): time, qpos, qvel; the first row is the scratch's state on entry.
        """
        m, s = self.model, self._tail_data
        nq = m.nq
        # One row (time, qpos, qvel) per substep, written by mj_getState. The stop test
        # (every |qvel| <= vel_tol) runs vectorised once per chunk of substeps (chunks of
        # 1, 2, 4, 8, 16, then _TAIL_CHUNK: a tail at rest stops after one substep as before); the
        # tail ends at the first substep that passes it, exactly as a per-substep test
        # would (substeps simulated beyond it in the same chunk only touch the private
        # scratch).
        rows = np.empty((n + 1, 1 + nq + m.nv))
        mujoco.mj_getState(m, s, rows[0], _TAIL_ROW)
        end = n
        k = 0
        chunk = 1
        while k < n:
            hi = min(k + chunk, n)
            chunk = min(2 * chunk, _TAIL_CHUNK)
            for j in range(k + 1, hi + 1):
                mujoco.mj_step(m, s)
                mujoco.mj_getState(m, s, rows[j], _TAIL_ROW)
            if m.nv == 0:
                end = k + 1
                break
            first = _first_at_rest(rows[k + 1:hi + 1, 1 + nq:], vel_tol)
            if first is not None:
                end = k + 1 + first  # the first substep that passes
                break
            k = hi
        return rows[:end + 1]

    def _tail_by_rollout(self, n: int, vel_tol: float) -> np.ndarray | None:
        """The tail of :meth:`_tail_by_loop` by ``mujoco.rollout`` (C, no Python per substep).

        Why it is the same computation: ``rollout`` sets the scratch's full physics state
        (``mjSTATE_FULLPHYSICS``: time, qpos, qvel, act, history, plugin, plastic), its
        ``qacc_warmstart`` and, before every substep, the user inputs (``mjSTATE_USER``:
        ctrl, applied forces, mocap, eq_active, userdata) -- all taken from the scratch
        itself, so together exactly its integration state -- then calls ``mj_step`` and
        reads the full physics state, whose first ``1 + nq + nv`` entries are the loop's
        row (time, qpos, qvel). Re-setting the user inputs each substep writes the values
        they already have, because ``mj_step`` never writes them when no callback or plugin
        is installed (:func:`_rollout_is_exact`). Consecutive chunks continue from the
        last state and warm start exactly. ``rollout`` stops stepping at a MuJoCo warning
        (and fills the rest with the last state) where the loop goes on: any warning
        returns None and the caller runs the loop.

        The first substep is one ``mj_step`` as in the loop (a tail at rest stops there);
        all the others run in one ``rollout`` call (a call costs ~10-15 µs of fixed
        overhead here, more than a substep; a tail that stops midway simulates substeps
        past its end, which only touch the private scratch).

        Precondition (as :meth:`brake_rows` calls it): the tail scratch's integration state
        is ``_end_state`` and its ``ctrl`` the brake control.

        Returns:
            rows (K, 1 + nq + nv) as :meth:`_tail_by_loop`, or None after a warning.
        """
        m, s = self.model, self._tail_data
        if self._roll is None:
            from mujoco import _rollout

            self._roll = _rollout.Rollout(nthread=0)  # runs on the calling thread
            self._n_full = mujoco.mj_stateSize(m, _FULL)
            self._n_user = mujoco.mj_stateSize(m, _USER)
        nq, nv = m.nq, m.nv
        ncol = 1 + nq + nv
        rows = np.empty((n + 1, self._n_full))  # full physics state per waypoint
        # Row 0: the scratch's state as set from _end_state (both layouts begin with time,
        # qpos, qvel); only its first ncol entries are returned.
        rows[0, :ncol] = self._end_state[:ncol]
        # Substep 1 exactly as the loop runs it (a tail at rest stops here).
        mujoco.mj_step(m, s)
        mujoco.mj_getState(m, s, rows[1], _FULL)
        if n == 1 or _row_at_rest(rows[1, 1 + nq:ncol].tolist(), vel_tol):
            return rows[:2, :ncol]
        # Substeps 2..n in one rollout call from the scratch's state after substep 1.
        bufs = self._tail_bufs
        if bufs is None or bufs[0].shape[1] != n - 1:
            # (user inputs held over the tail, warm start, warning counters: views of the scratch,
            # and the counters' bytes when all are 0)
            counters = s.warning.number
            bufs = self._tail_bufs = (np.empty((1, n - 1, self._n_user)), np.empty((1, nv)), counters,
                                      s.qacc_warmstart, bytes(counters.nbytes))
        user, warm, counters, s_warm, no_warning = bufs
        mujoco.mj_getState(m, s, user[0, 0], _USER)
        user[0, 1:] = user[0, 0]
        warm[0] = s_warm
        counters[:] = 0
        self._roll.rollout([m], [s], n - 1, _USER, rows[1:2], warm, user, rows[None, 2:], None, None)
        if counters.tobytes() != no_warning:  # some counter is not 0 (integers: bytes 0 <=> value 0)
            return None
        first = _first_at_rest(rows[2:, 1 + nq:ncol], vel_tol)
        end = n if first is None else 2 + first  # the first substep that passes
        return rows[:end + 1, :ncol]


def _row_at_rest(qvel: list[float], vel_tol: float) -> bool:
    """Whether every ``|v| <= vel_tol`` in one row of qvel given as a list (the stop rule of one substep).

    The same answer as ``np.abs(row).max() <= vel_tol``, without two numpy calls on a few entries
    (~1.2 µs against 0.3-0.9): a NaN entry fails (numpy's ``max`` is then NaN, and ``NaN <= tol``
    is False), as does any entry above ``vel_tol``; a NaN ``vel_tol`` fails every row in both.
    Python floats are the float64 values exactly (``tolist``), compared in the same IEEE order.
    ``vel_tol`` is taken as a Python float first: numpy 2 compares a Python float with a numpy
    float32 / float16 scalar in that narrower type (NEP 50), where numpy's form compares in float64
    (red team 19: a row just above a float32 tolerance passed).
    """
    vel_tol = float(vel_tol)
    for v in qvel:
        if not abs(v) <= vel_tol:
            return False
    return True


def _first_at_rest(qvel: np.ndarray, vel_tol: float) -> int | None:
    """Index of the first row of ``qvel`` (K, nv), nv >= 1, with every ``|qvel| <= vel_tol``, else None.

    The braking tail's stop rule. A NaN entry fails its row (as ``max(|row|) <= vel_tol`` does).
    Without numpy's per-row reduction over nv columns (slow for short rows: ~10 µs for a
    125-substep Arm tail): a row passes only if its first entry does, so only the first column
    is tested for every row (three numpy calls on K entries: ~1 µs against ~3 for the whole
    (K, nv) block), and only the rows whose first entry passes are tested whole (few or none
    while the bodies move); ``nonzero`` gives them in increasing order, so the first of them
    that passes whole is the first row that passes.
    """
    cand = (np.abs(qvel[:, 0]) <= vel_tol).nonzero()[0]  # rows whose first entry passes, (c,) increasing
    if cand.size:
        cand = cand[(np.abs(qvel[cand]) <= vel_tol).all(axis=1)]
    return int(cand[0]) if cand.size else None


_FULL = mujoco.mjtState.mjSTATE_FULLPHYSICS
_USER = mujoco.mjtState.mjSTATE_USER
_CALLBACK_GETTERS = tuple(getattr(mujoco, f"get_mjcb_{name}") for name in (
    "control", "passive", "act_dyn", "act_gain", "act_bias", "sensor", "contactfilter", "time"))


def _rollout_is_exact(model: mujoco.MjModel) -> bool:
    """Whether ``mujoco.rollout`` of a held control is exactly the ``mj_step`` loop.

    See :meth:`Rollout._tail_by_rollout`: degrees of freedom to test for the stop rule, no
    plugin and no global callback (either could write the user inputs inside ``mj_step``,
    which the rollout re-sets every substep).
    """
    if model.nv == 0 or model.nplugin != 0:
        return False
    for get in _CALLBACK_GETTERS:  # read on every call: a callback can be installed at any time
        if get() is not None:
            return False
    return True


_AFFINE = int(mujoco.mjtBias.mjBIAS_AFFINE)
_FIXED = int(mujoco.mjtGain.mjGAIN_FIXED)
_TRN_JOINT = int(mujoco.mjtTrn.mjTRN_JOINT)
_HINGE_SLIDE = (int(mujoco.mjtJoint.mjJNT_HINGE), int(mujoco.mjtJoint.mjJNT_SLIDE))


_HOLD_STRUCT = ("actuator_trntype", "actuator_biastype", "actuator_gaintype", "actuator_trnid", "jnt_type",
                "jnt_qposadr", "actuator_ctrllimited")
_HOLD_VALUES = ("actuator_gainprm", "actuator_biasprm", "actuator_gear", "actuator_ctrlrange")
_HOLD_CACHE: dict[int, list[Any]] = {}
_HOLD_CACHE_MAX = 16


def _hold_plan(model: mujoco.MjModel) -> tuple[np.ndarray, np.ndarray, np.ndarray | None, bool,
                                               tuple[np.ndarray, ...]]:
    """Which actuators :func:`hold_ctrl` computes, from the model's CURRENT structure arrays.

    Returns (a, adr, limited, whole, values): the position-like actuators on a hinge / slide joint
    by structure alone (joint transmission, affine bias, fixed gain; the value conditions
    ``gain != 0``, ``biasprm[1] != 0`` are tested per call), the qpos address of each one's
    joint, the ctrl-limited actuators (None: every actuator), whether ``a`` is every actuator in
    order, and views of the value columns used (gainprm[:, 0], biasprm[:, 0], biasprm[:, 1],
    gear[:, 0], ctrlrange[:, 0], ctrlrange[:, 1]: the model's own buffers, so in-place edits are
    seen). Cached per model
    object and keyed on the bytes of every structure array read (an in-place edit of one of
    them recomputes it); MjModel array views never move, so the cached views stay valid.
    """
    hit = _HOLD_CACHE.get(id(model))
    if hit is None or hit[0] is not model:
        if len(_HOLD_CACHE) >= _HOLD_CACHE_MAX:
            _HOLD_CACHE.pop(next(iter(_HOLD_CACHE)))
        gainprm, biasprm, gear, ctrlrange = (getattr(model, f) for f in _HOLD_VALUES)
        # column views (gain, bias 0, bias 1, gear, lower, upper): the model's memory, read live
        hit = [model, [getattr(model, f) for f in _HOLD_STRUCT],
               (gainprm[:, 0], biasprm[:, 0], biasprm[:, 1], gear[:, 0], ctrlrange[:, 0], ctrlrange[:, 1]),
               None, None]
        _HOLD_CACHE[id(model)] = hit  # the model reference keeps id(model) unique
    struct = hit[1]
    key = b"|".join([v.tobytes() for v in struct])
    if hit[3] != key:
        trntype, biastype, gaintype, trnid, jnt_type, jnt_qposadr, ctrllimited = struct
        j = trnid[:, 0]
        a = np.flatnonzero((trntype == _TRN_JOINT) & (biastype == _AFFINE) & (gaintype == _FIXED))
        jt = jnt_type[j[a]]
        a = a[(jt == _HINGE_SLIDE[0]) | (jt == _HINGE_SLIDE[1])]
        limited = np.flatnonzero(ctrllimited.astype(bool))
        # whole: a is every actuator in order; limited None: every actuator (the clip runs on
        # whole columns)
        hit[4] = (a, jnt_qposadr[j[a]].copy(), None if limited.size == len(ctrllimited) else limited,
                  bool(np.array_equal(a, np.arange(len(trntype)))))
        hit[3] = key
    a, adr, limited, whole = hit[4]
    return a, adr, limited, whole, hit[2]


def hold_ctrl(model: mujoco.MjModel, data: mujoco.MjData) -> np.ndarray:
    """A control that holds the current position where the actuators allow it.

    Position-like actuators (affine bias with a length term, e.g. ``<position>``)
    on a hinge or slide joint get the control whose force vanishes at the
    current joint position: ``ctrl = -(biasprm[0] + biasprm[1] * gear * q) / gainprm[0]``
    (``= gear * q`` for ``<position>``). Every other actuator gets 0 (a velocity
    servo then brakes, a motor coasts). The result is clipped to ``ctrlrange``
    where the control is limited.

    Vectorised over the actuators and read from the live model on every call (a model
    edited in place, e.g. a randomised gain, is used as it is now: the structure arrays
    are compared byte for byte with the cached selection, the values are read live); the
    same operations per actuator as the scalar formula, so the same floats.

    Returns:
        (nu,) float64 control.
    """
    nu = model.nu
    if nu == 0:
        return np.zeros(0)
    a, adr, limited, whole, (gain0, bias0, bias1, gear0, lo, hi) = _hold_plan(model)
    if whole and gain0.all() and bias1.all():
        # every actuator position-like, in order, gain and biasprm[1] nonzero (ndarray.all():
        # no element == 0, as the test below): the same operations on whole columns
        ctrl = -(bias0 + bias1 * (gear0 * data.qpos[adr])) / gain0
    else:
        ctrl = np.zeros(nu)
        if a.size:
            gain = gain0[a]
            b1 = bias1[a]
            ok = (gain != 0.0) & (b1 != 0.0)
            if not ok.all():
                a, adr, gain, b1 = a[ok], adr[ok], gain[ok], b1[ok]
            if a.size:
                length = gear0[a] * data.qpos[adr]
                ctrl[a] = -(bias0[a] + b1 * length) / gain
    # ndarray.clip is what np.clip calls for an ndarray (numpy's _wrapfunc), without its
    # argument handling and dispatch: the same clip ufunc, the same floats
    if limited is None:  # every actuator limited
        return ctrl.clip(lo, hi)
    if limited.size:
        ctrl[limited] = ctrl[limited].clip(lo[limited], hi[limited])
    return ctrl


# --------------------------------------------------------------------------- reports
class _WindowRows:
    """The rollout's window (the read-only rows of :meth:`Rollout._window`); its Plan built on first use.

    :attr:`plan` is exactly :meth:`Rollout.plan`'s Plan (the same times and qpos, copied from
    the rows when it is built; the live data's mocap copied when the window was predicted).
    The joint call certifies the window without it; the two-call path, a log and
    :attr:`StepReport.plan` build it.
    """

    __slots__ = ("rows", "_model", "_mocap_pos", "_mocap_quat", "_plan", "key")

    def __init__(self, rows: np.ndarray, model: mujoco.MjModel, data: mujoco.MjData,
                 key: tuple[bytes, bytes, int] | None = None) -> None:
        self.rows = rows  # (K, 1 + nq) time (s), qpos; read-only
        self.key = key  # the rollout's window_key for these rows (a log's ``rollout``), or None
        self._model = model
        self._mocap_pos = np.array(data.mocap_pos)
        self._mocap_quat = np.array(data.mocap_quat)
        self._plan: Any = None

    @property
    def plan(self) -> Any:
        """The window's :class:`monitor.Plan`."""
        if self._plan is None:
            from monitor.motion.plan import Plan

            rows = self.rows  # fresh owned copies: the Plan normalises its qpos in place
            self._plan = Plan._trusted(rows[:, 0].copy(), rows[:, 1:].copy(), model=self._model,
                                       mocap_pos=self._mocap_pos, mocap_quat=self._mocap_quat)
        return self._plan

    @property
    def times(self) -> np.ndarray:
        """(K,) waypoint times (s): a read-only view of the rows."""
        return self.rows[:, 0]

    @property
    def t0(self) -> float:
        """Window start (s), as the Plan's ``t0``."""
        return float(self.rows[0, 0])

    @property
    def t1(self) -> float:
        """Window end (s), as the Plan's ``t1``."""
        return float(self.rows[-1, 0])


def _plan_of(p: Any) -> Any:
    """A Plan from a Plan, a :class:`_WindowRows` or a :class:`_Tail`."""
    return p.plan if isinstance(p, (_WindowRows, _Tail)) else p


class _LazyPlanField:
    """Descriptor of :attr:`StepReport.plan`: a :class:`_WindowRows` becomes its Plan on first read.

    The Plan is then kept. The dataclass sees a field with default None;
    ``report.plan = x`` still raises ``FrozenInstanceError``.
    """

    def __set_name__(self, owner: type, name: str) -> None:
        self._slot = f"_{name}_store"

    def __get__(self, obj: Any, objtype: type | None = None) -> Any:
        if obj is None:
            return None
        v = obj.__dict__.get(self._slot)
        if isinstance(v, _WindowRows):
            v = obj.__dict__[self._slot] = v.plan
        return v

    def __set__(self, obj: Any, value: Any) -> None:
        obj.__dict__[self._slot] = value


@dataclass(frozen=True)
class StepReport:
    """What the gate decided for one window.

    Attributes:
        verdict: verdict of the *proposed* control's window.
        certificate: certificate of the proposed window.
        proposed_ctrl: (nu,) control (or env action) proposed by the caller.
        applied_ctrl: (nu,) control actually applied (the fallback when replaced).
        replaced: True when the proposed control was replaced by the fallback.
        terminated: True when ``on_violation="terminate"`` and the proposal was unsafe.
        unsafe: True when the proposed window counted as unsafe (see ``unsafe=``).
        applied_verdict: verdict of the window actually applied (= ``verdict``
            unless replaced).
        fallback_certificate: certificate of the fallback window (or of the committed
            braking tail that contains it, see ``brake``), or None.
        fallback_certified: False only when a fallback was applied whose window
            did not certify.
        certify_us: wall time (µs) spent certifying (proposal, brake tail, fallback).
        time: window start (s).
        brake_verdict: verdict of the braking tail after the proposed window, a
            :class:`monitor.Verdict` (``""`` when not checked: brake check off, ``"warn"``, or
            proposal unsafe).
        plan: the proposed window's plan.
        stepped: True when :meth:`Gate.step` advanced the caller's data.
    """

    verdict: str
    certificate: Certificate
    proposed_ctrl: np.ndarray
    applied_ctrl: np.ndarray
    replaced: bool
    terminated: bool
    unsafe: bool
    applied_verdict: str
    fallback_certificate: Certificate | None
    fallback_certified: bool
    certify_us: float
    time: float
    plan: Any = _LazyPlanField()  # type: ignore[assignment]  # a Plan (built on first read)
    stepped: bool = False
    brake_verdict: str = ""

    @classmethod
    def _trusted(cls, verdict: str, certificate: Certificate, proposed_ctrl: np.ndarray,
                 applied_ctrl: np.ndarray, replaced: bool, terminated: bool, unsafe: bool,
                 applied_verdict: str, fallback_certificate: Certificate | None, fallback_certified: bool,
                 certify_us: float, time: float, plan: Any, brake_verdict: str) -> StepReport:
        """The report ``StepReport(...)`` makes (``stepped=False``), without the frozen ``__init__``.

        The frozen dataclass's ``__init__`` sets each of its 15 fields by ``object.__setattr__``;
        this writes the same instance ``__dict__`` at once (``plan`` under the slot of
        :class:`_LazyPlanField`). ``tests/test_gate_plumbing.py`` compares the two.
        """
        r = object.__new__(cls)
        r.__dict__.update(verdict=verdict, certificate=certificate, proposed_ctrl=proposed_ctrl,
                          applied_ctrl=applied_ctrl, replaced=replaced, terminated=terminated, unsafe=unsafe,
                          applied_verdict=applied_verdict, fallback_certificate=fallback_certificate,
                          fallback_certified=fallback_certified, certify_us=certify_us, time=time,
                          _plan_store=plan, stepped=False, brake_verdict=brake_verdict)
        return r

    def _stepped(self) -> StepReport:
        """A copy with ``stepped=True`` (= ``dataclasses.replace``, without building the plan)."""
        r = object.__new__(type(self))
        state = r.__dict__
        state.update(self.__dict__)
        state["stepped"] = True
        return r

    @property
    def cost(self) -> float:
        """1.0 when the APPLIED window has a confirmed violation, else 0.0.

        safety-gymnasium's convention: the cost of the transition that happened; the
        proposal's own cost is ``info()["proposal_cost"]``.
        """
        return applied_cost(self)

    @property
    def block_reason(self) -> str:
        """Why the proposal was replaced (``""`` if not); see :mod:`monitor.gate_policy`."""
        return block_reason(self)

    def info(self, *, timing: bool = False) -> dict[str, Any]:
        """Fixed-shape summary for ``info["safety"]`` (stackable by vector envs).

        Absent values are ``inf`` (times, witness point) and ``""`` (geoms), not
        NaN, so that two identical runs compare equal (gymnasium's determinism
        checks use ``==`` / ``allclose``, for which NaN != NaN). String arrays are
        object arrays (``allclose`` cannot compare numpy str arrays).

        Args:
            timing: include ``certify_us`` (wall time: differs between identical runs).

        Returns:
            dict with verdict (str), applied_verdict (str), brake_verdict (str), checker ((P,) object array
            of str, one per candidate pair), checker_mix (str, e.g. ``"culled:12 toleranced:3"``),
            witness_time (float s), witness_geoms ((2,) object array of str), witness_point ((3,) m),
            earliest_time (float s), clearance (float m), replaced (bool),
            fallback_certified (bool), terminated (bool), time (float s), monitored_pairs (int:
            candidate pairs checked, 0 when the gate monitors nothing),
            version (int), proposal_cost (float), intervened (bool), block_reason (str)
            (:mod:`monitor.gate_policy`) and, if ``timing``, certify_us (float µs).
        """
        out = safety_info(self.certificate, verdict=self.verdict, applied_verdict=self.applied_verdict,
                          replaced=self.replaced, fallback_certified=self.fallback_certified,
                          terminated=self.terminated, time=self.time, brake_verdict=self.brake_verdict,
                          certify_us=self.certify_us if timing else None)
        out.update(safety_keys(self))
        return out


def _all_culled(cert: Certificate) -> int | None:
    """The number of pairs if every one of them was decided by the broad phase (0: no pair), else None.

    From the certificate's documented stats (``pairs``: the pair count; ``checker_mix``:
    ``{method: count}``), without building its :class:`PairResult` tuple (the engine builds
    it lazily, ~50-100 µs per gated Pusher step): ``checker_mix == {"culled": pairs}`` means
    each pair's ``method`` is ``"culled"``. ``tests/test_gate_reports.py`` checks it against
    the built pairs.
    """
    stats = cert.stats
    n = stats.get("pairs")
    mix = stats.get("checker_mix")
    if type(n) is int and type(mix) is dict and (mix.get("culled") == n > 0 and len(mix) == 1
                                                 or n == 0 and not mix):  # 0 pairs: nothing to build
        return n
    return None


def _npairs(cert: Certificate) -> int:
    """``len(cert.pairs)`` without building the pairs: the documented ``stats["pairs"]``.

    Every certificate ``certify`` and the gate make has ``stats["pairs"] == len(pairs)``
    (checked against the built pairs on seeded tunnel / Pusher / Arm episodes in
    ``tests/test_gate_reports.py``); a certificate without it is counted by its pairs.
    """
    n = cert.stats.get("pairs")
    return n if type(n) is int else len(cert.pairs)


_NO_GEOMS = np.array(["", ""], dtype=object)  # templates, copied into each info dict (never handed out)
_NO_POINT = np.full(3, math.inf)
_CULLED: dict[int, np.ndarray] = {}


def _culled_methods(n: int) -> np.ndarray:
    """A fresh (n,) object array of ``"culled"`` (a copy of a cached template)."""
    t = _CULLED.get(n)
    if t is None:
        if len(_CULLED) >= 64:
            _CULLED.clear()
        t = _CULLED[n] = np.full(n, "culled", dtype=object)
    return t.copy()


def safety_info(cert: Certificate | None, *, verdict: str, applied_verdict: str, replaced: bool,
                fallback_certified: bool, terminated: bool, time: float, brake_verdict: str = "",
                certify_us: float | None = None, npairs: int | None = None) -> dict[str, Any]:
    """Build the fixed-shape ``info["safety"]`` dict (see :meth:`StepReport.info`).

    With ``cert=None`` (e.g. after ``reset``) the checker array has ``npairs`` entries of ``""``.
    """
    inf = math.inf
    if cert is None:
        checker = np.full(int(npairs or 0), "", dtype=object)
        mix, wit, earliest, clearance = "", None, inf, inf
    else:
        n = _all_culled(cert)
        if n is not None:  # every pair culled (the common gated step): no PairResult is built
            checker = _culled_methods(n)
            mix = f"culled:{n}" if n else ""
        else:
            checker = cert.pair_methods()   # no PairResult built on the compiled path
            names = checker.tolist()
            # counts per method (list.count: a few distinct names), code-point order as np.unique
            mix = " ".join(f"{m}:{names.count(m)}" for m in sorted(set(names)))
        wit = cert.witness
        earliest = inf if cert.earliest_time is None else float(cert.earliest_time)
        clearance = float(cert.clearance)
    out = {
        "verdict": verdict,
        "applied_verdict": applied_verdict,
        "brake_verdict": brake_verdict,
        "checker": checker,
        "checker_mix": mix,
        "witness_time": inf if wit is None else float(wit.time),
        "witness_geoms": _NO_GEOMS.copy() if wit is None else np.array(list(wit.geoms), dtype=object),
        "witness_point": _NO_POINT.copy() if wit is None else np.asarray(wit.point, float).reshape(3).copy(),
        "earliest_time": earliest,
        "clearance": clearance,
        "replaced": bool(replaced),
        "fallback_certified": bool(fallback_certified),
        "terminated": bool(terminated),
        "time": float(time),
        "monitored_pairs": int(len(checker)),
    }
    if certify_us is not None:
        out["certify_us"] = float(certify_us)
    return out


# --------------------------------------------------------------------------- the gate
class _Tail:
    """A braking tail's rows (from :meth:`Rollout.brake_rows`); its Plan is built on first use.

    The joint call certifies the tail without its own Plan; only the two-call path and
    :meth:`Gate._tail_covers` (a later rejected proposal) read :attr:`plan`, the same Plan
    :meth:`Rollout.brake_tail` builds (same rows, mocap copied from the live data).
    """

    __slots__ = ("rows", "qvel", "mocap_pos", "mocap_quat", "_model", "_plan", "_plan_mocap_quat", "key")

    def __init__(self, rows: np.ndarray, model: mujoco.MjModel, data: mujoco.MjData,
                 key: tuple[tuple[bytes, bytes, int] | None, np.ndarray] | None = None) -> None:
        nq = model.nq
        self.key = key  # (the window's Rollout.window_key, brake ctrl (nu,)) it continues, or None
        self.rows = rows[:, :1 + nq]  # (K, 1 + nq) time, qpos
        self.qvel = rows[:, 1 + nq:].copy()  # (K, nv)
        self.mocap_pos = np.array(data.mocap_pos)  # held over the window and the tail
        self.mocap_quat = np.array(data.mocap_quat)
        self._model = model
        self._plan: Any = None
        self._plan_mocap_quat: np.ndarray | None = None

    def plan_qpos_row(self, k: int) -> np.ndarray:
        """(nq,) ``plan.qpos[k]``, without building the Plan when the rows are its qpos.

        The Plan copies the rows' qpos and changes them only by normalising ball / free
        quaternions; a model without such joints (``nq == nv``: hinge and slide joints have
        one qpos entry per dof, ball 4 for 3, free 7 for 6) has none, so its row ``k`` is the
        rows' row ``k`` bit for bit. Else (or once built) the Plan's own row.
        """
        m = self._model
        if self._plan is None and m.nq == m.nv:
            return self.rows[k, 1:]
        return self.plan.qpos[k]

    def plan_mocap_quat(self) -> np.ndarray:
        """(nmocap, 4) ``plan.mocap_quat``, without building the Plan.

        The Plan's held mocap quaternions are ``monitor.motion.plan._normalized`` of the
        copy it gets (``Plan._setup``, default tolerances as in :attr:`plan`), or its
        ``normalize_quats`` error when a norm is out of tolerance: the same function of the
        same bytes here; a norm out of tolerance builds the Plan (which raises as before).
        No mocap body: the (0, 4) array as given.
        """
        if self._plan is not None:
            return self._plan.mocap_quat
        q = self._plan_mocap_quat
        if q is None:
            mq = self.mocap_quat
            if not mq.size:
                q = mq
            else:
                from monitor.motion.plan import _normalized

                q = _normalized(mq, DEFAULT)
                if q is None:
                    return self.plan.mocap_quat  # raises (see above)
            self._plan_mocap_quat = q
        return q

    @property
    def plan(self) -> Any:
        """The tail's :class:`monitor.Plan`."""
        if self._plan is None:
            from monitor.motion.plan import Plan

            self._plan = Plan._trusted(self.rows[:, 0].copy(), self.rows[:, 1:].copy(), model=self._model,
                                       mocap_pos=self.mocap_pos.copy(), mocap_quat=self.mocap_quat.copy())
        return self._plan


def _part(cert: Certificate, window: tuple[float, float], span: list[float]) -> Certificate:
    """``cert`` (certified over ``span``) as the certificate of the sub-window ``window``.

    A shallow copy (the pair results, possibly not built yet, are shared); ``window`` and
    ``stats`` are its own.
    """
    out = object.__new__(type(cert))  # = copy.copy(cert) (a dataclass: its __dict__ is its state)
    state = out.__dict__
    state.update(cert.__dict__)
    state["window"] = window
    state["stats"] = {**cert.stats, "joint_window": span}
    return out


def _json_items(items: Any) -> Any:
    """``hazards=`` / ``allow=`` pattern items as JSON (one string stays one item; pairs -> lists)."""
    if items is None or isinstance(items, str):
        return items
    return [x if isinstance(x, str) else [str(v) for v in x] for x in items]


_MODEL_EDITS_KEY = "model_edits"
"""Run metadata key ``monitor.log.topics.MODEL_EDITS_KEY`` (spelled here: gate.py imports no mcap)."""
_ROLLOUTS_KEY = "rollouts"
"""Run metadata key ``monitor.log.topics.ROLLOUTS_KEY``: every window says where its rows come from."""


def _not_replayable(*windows: Any) -> None:
    """Forget the rollout keys of ``windows`` (their rows are logged as not re-simulable, ``"user"``)."""
    for w in windows:
        if isinstance(w, (_WindowRows, _Tail)):
            w.key = None


def _logged_rollout(p: Any) -> Any:
    """What a log records of where the rows of window ``p`` come from (``MonitorLog.write_window(rollout=)``).

    A :class:`_WindowRows` or :class:`_Tail` of the gate's own rollout: ``(state, segments, rows_from)``,
    the integration state (``mjSTATE_INTEGRATION`` bytes) the rows were simulated from, the controls
    held over consecutive substeps ``((ctrl, substeps), ...)`` and the substep of the first row (a
    braking tail is simulated after its window: rows from substep ``nstep``). Anything else (a user
    predictor's or adapter's Plan, an explicit Plan), or rows simulated while a global MuJoCo
    callback (``mjcb_control``, ...: user code inside ``mj_step``) is installed: ``"user"``, not
    re-simulable.
    """
    key = p.key if isinstance(p, (_WindowRows, _Tail)) else None
    if key is not None and any(get() is not None for get in _CALLBACK_GETTERS):
        return "user"
    if isinstance(p, _Tail) and key is not None:
        window, brake = key
        if window is None:
            return "user"
        state, ctrl, n = window
        return state, ((ctrl, n), (brake, len(p.rows) - 1)), n
    if key is None:
        return "user"
    state, ctrl, n = key
    return state, ((ctrl, n),), 0


def _check_predictor(predictor: Any) -> Any:
    """``predictor``: ``"rollout"`` or a callable, else InvalidInputError."""
    if not (callable(predictor) or (isinstance(predictor, str) and predictor in PREDICTORS)):
        raise InvalidInputError(f"predictor must be 'rollout' or a callable, got {predictor!r}")
    return predictor


MAX_WINDOW_STEPS = 100_000
"""Most substeps one window may take (``nstep``, ``frame_skip``): the rollout allocates (nstep + 1, 1 + nq)
rows and simulates them before anything is certified, so ``nstep=10**9`` would exhaust memory or run
for hours (red team 10) instead of failing. 100 000 substeps is 200 s at MuJoCo's default 2 ms
timestep, far beyond any gated step; the same bound as :data:`MAX_BRAKE_STEPS`."""


def _check_nstep(n: Any, name: str) -> int:
    """``n`` as a substep count in [1, :data:`MAX_WINDOW_STEPS`], else InvalidInputError.

    Not a bool, a float or a string.
    """
    if isinstance(n, (bool, np.bool_)) or not isinstance(n, (int, np.integer)) or n < 1:
        raise InvalidInputError(f"{name} must be an integer >= 1, got {n!r}")
    if n > MAX_WINDOW_STEPS:
        raise InvalidInputError(
            f"{name} = {n!r} substeps is more than one window may take ({MAX_WINDOW_STEPS}; the rollout "
            f"simulates and stores every substep before certifying): certify a long motion as "
            f"several windows")
    return int(n)


def _check_data(model: mujoco.MjModel, data: Any) -> None:
    """InvalidInputError unless ``data`` is an ``MjData`` of ``model`` (or of an identical copy of it).

    ``data.model`` (the ``MjModel`` the data was made for) is ``model`` on the usual path; another
    object must serialise to the same bytes (``mj_saveModel``: a pickled gate stepping the
    original's data). Sizes alone let through the data of an edited copy (a moved obstacle: the
    gate certified its own model's window, the caller's model ran another; red team 10) or of a
    model with other array sizes (``mj_copyData`` then raised ``mujoco.FatalError``).
    """
    if not isinstance(data, mujoco.MjData):
        raise InvalidInputError(f"data must be a mujoco.MjData, got {type(data).__name__}")
    if data.qpos.shape[0] != model.nq or data.qvel.shape[0] != model.nv or data.ctrl.shape[0] != model.nu:
        raise InvalidInputError(
            f"data has nq={data.qpos.shape[0]}, nv={data.qvel.shape[0]}, nu={data.ctrl.shape[0]} but the "
            f"gate's model has nq={model.nq}, nv={model.nv}, nu={model.nu}: MjData of another model")
    own = getattr(data, "model", model)
    if own is not model:
        from monitor.scene import model_hash

        if model_hash(own) != model_hash(model):
            raise InvalidInputError(
                "data was made for another MjModel than the gate's (data.model is not gate.model and differs "
                "from it): the gate certifies windows of its own model; build the gate on data.model, or "
                "edit gate.model in place (the gate re-reads it every step)")


def _check_ctrl(ctrl: np.ndarray, shape: tuple[int, ...]) -> None:
    """Typed errors for a control :meth:`Gate.decide` cannot certify.

    ``ctrl`` (already an array) must be numeric, finite and of the gate's action shape: MuJoCo
    silently zeroes a NaN control (``mjWARN_BADCTRL``), so without this check a NaN proposal
    would come back ``certified`` for a motion under another control.
    """
    if ctrl.dtype.kind not in "fiub" or ctrl.shape != shape:
        raise InvalidInputError(f"ctrl must be a numeric array of shape {shape}, got {ctrl!r}")
    if not np.isfinite(ctrl).all():
        raise InvalidInputError(f"ctrl contains NaN or inf: {ctrl!r}")


def _make_budget(budget: Any) -> Any:
    """A fresh :class:`Budget` per certification from the user's spec (or None)."""
    if budget is None:
        return None
    from monitor.certify.common import Budget

    if isinstance(budget, Budget):
        return Budget(seconds=_budget_seconds(budget.seconds), tests=_budget_tests(budget.tests))
    if isinstance(budget, dict):
        unknown = sorted(str(k) for k in budget if k not in ("seconds", "tests"))
        if unknown:
            raise InvalidInputError(f"budget: unknown keys {unknown}; use 'seconds' and/or 'tests'")
        return Budget(seconds=_budget_seconds(budget.get("seconds")),
                      tests=_budget_tests(budget.get("tests")))
    bad = f"budget must be seconds (float), tests (int), a dict or a Budget; got {budget!r}"
    if isinstance(budget, bool):
        raise InvalidInputError(bad)
    if isinstance(budget, (int, np.integer)):
        return Budget(tests=_budget_tests(budget))
    if isinstance(budget, (float, np.floating)):
        return Budget(seconds=_budget_seconds(budget))
    raise InvalidInputError(bad)


def _is_real(x: Any) -> bool:
    """True for a real number (Python or numpy int/float), False for bool and everything else."""
    return (not isinstance(x, (bool, np.bool_))
            and isinstance(x, (int, float, np.integer, np.floating)))


def _budget_seconds(seconds: Any) -> float | None:
    """Validated ``budget`` seconds: None or a finite number > 0."""
    if seconds is None:
        return None
    if not _is_real(seconds) or not math.isfinite(float(seconds)) or float(seconds) <= 0:
        raise InvalidInputError(f"budget seconds must be a finite number > 0, got {seconds!r}")
    return float(seconds)


def _budget_tests(tests: Any) -> int | None:
    """Validated ``budget`` tests: None or an integer >= 1."""
    if tests is None:
        return None
    if isinstance(tests, (bool, np.bool_)) or not isinstance(tests, (int, np.integer)) or int(tests) < 1:
        raise InvalidInputError(f"budget tests must be an integer >= 1, got {tests!r}")
    return int(tests)


def _no_candidate_pairs(model: mujoco.MjModel, pairs: Any) -> bool:
    """True when ``pairs`` ("mujoco"/"all") selects no geom pair before any allowed-contact matrix.

    MuJoCo's own filter only: no shapes are built. Explicit lists are validated by the scene.
    """
    if not isinstance(pairs, str):
        return False
    from monitor.scene import _filter_pairs

    try:
        return len(_filter_pairs(model, pairs)) == 0
    except Exception:  # noqa: BLE001 - an unknown mode is reported by Scene.from_model, with its name
        return False


def _check_log(log: Any) -> None:
    """``log`` must be None, a path or an object with ``write_window`` (a MonitorLog)."""
    if isinstance(log, (str, os.PathLike)):
        try:  # like MonitorLog: a missing directory is created (the README's log="logs/arm.mcap")
            Path(log).parent.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise InvalidInputError(f"log: cannot create the directory of {str(log)!r}: {exc}") from exc
        return
    if log is None or callable(getattr(log, "write_window", None)):
        return
    raise InvalidInputError(f"log must be None, an .mcap path or a monitor.log.MonitorLog, got "
                            f"{type(log).__name__} {log!r}")


def _finite_setting(value: Any, name: str, *, positive: bool, what: str) -> float:
    """``value`` as a finite float, > 0 (``positive``) or >= 0, else InvalidInputError naming ``name``."""
    try:
        x = float(value)
    except (TypeError, ValueError):
        x = math.nan
    if isinstance(value, bool) or not math.isfinite(x) or x < 0.0 or (positive and x == 0.0):
        raise InvalidInputError(f"{name} must be a finite number{what} {'> 0' if positive else '>= 0'}, "
                                f"got {value!r}")
    return x


def _check_fallback(fallback: Any, shape: tuple[int, ...]) -> Any:
    """``fallback`` must be None, a callable or a finite array of ``shape``; returns the stored value."""
    if fallback is None or callable(fallback):
        return fallback
    try:
        arr = np.array(fallback, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise InvalidInputError(f"fallback must be None, a callable or a numeric array of shape {shape}, "
                                f"got {fallback!r}") from e
    if arr.shape != shape:
        raise InvalidInputError(f"fallback must have shape {shape} (one value per actuator), got {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise InvalidInputError(f"fallback contains NaN or inf: {arr}")
    return arr


def _model_name(model: mujoco.MjModel) -> str:
    """The model's name (``<mujoco model="...">``), or ``""``."""
    return bytes(model.names).split(b"\0", 1)[0].decode(errors="replace")


MAX_BRAKE_STEPS = 100_000
"""Most substeps one braking tail may take (``brake_horizon / opt.timestep``); the tail's row buffers
are sized by it, so a tiny timestep or a huge horizon gets an :class:`InvalidInputError` rather than
an out-of-memory crash. 100 000 substeps is 200 s at MuJoCo's default 2 ms timestep."""


class Gate:
    """Certify-then-step gate on a caller's ``MjModel`` / ``MjData`` (no gymnasium).

    Args:
        model: the ``MjModel``.
        pairs: candidate pairs for :meth:`monitor.Scene.from_model` (``"mujoco"``,
            ``"all"`` or a list of geom-name pairs).
        margin: clearance (m) that counts as safe.
        epsilon: certification tolerance (m of body motion).
        predictor: ``"rollout"`` or a callable ``predictor(data, ctrl, nstep) -> Plan``.
        on_violation: ``"block" | "terminate" | "warn"``.
        unsafe: ``"uncertain"`` (anything not certified is unsafe) or ``"violation"``.
        fallback: None (hold position, see :func:`hold_ctrl`), a (nu,) array, or a
            callable ``fallback(data) -> ctrl``.
        budget: per-window work limit: seconds (float), tests (int), a dict
            ``{"seconds": .., "tests": ..}`` or a :class:`monitor.certify.common.Budget`.
            An exhausted budget makes the window "uncertain", never "certified".
        log: None, a path (``.mcap``) or a :class:`monitor.log.MonitorLog`; every
            window is written. A path in use by another live gate is not overwritten:
            the gate writes ``<stem>.1<suffix>``, ``<stem>.2<suffix>``, ... (see
            :attr:`log_path`).
        frame_skip: default number of substeps per window (``nstep``).
        reuse: reuse certified results of pairs whose bodies are fixed and unchanged.
        brake: recoverability check (``"block"``/``"terminate"`` with the default or
            an array fallback): a proposal is accepted only if, in addition to its
            own window, the braking tail after it (the fallback control held from
            the window's end state, see :meth:`Rollout.brake_tail`) is safe. That
            brake control is then *committed*: when a later proposal is rejected the
            gate applies the committed brake, whose motion was certified as that
            tail, instead of a fresh hold computed too late to stop in time. Without
            it a one-window gate can accept a proposal from which nothing can stop
            before the obstacle. Not available with a callable fallback (it cannot
            be evaluated at a predicted state).
        brake_horizon: longest braking tail (s of simulation time).
        brake_vel_tol: the tail ends once every ``|qvel|`` is at most this (rad/s, m/s).
        tolerances: numerical tolerances.
        log_options: extra keyword arguments for :class:`monitor.log.MonitorLog` when
            ``log`` is a path (e.g. ``env_id``, ``model_source``).
        allowed: allowed-contact matrix (:func:`monitor.acm.as_acm`). Default ``"auto"``:
            computed from the model when the scene is first needed (Adjacent + Default in
            the reference pose: the first state the gate sees, i.e. ``data.qpos`` at the first
            :meth:`decide` or an env's first reset, and its settled state + Always from a
            small seeded sample; cached per model hash and reference);
            None checks every candidate pair. Allowed pairs are never gated and are
            listed in every certificate with their reasons.
        hazards: None (every candidate pair) or pattern items (:mod:`monitor.pairsel`)
            selecting the checked pairs.
        allow: pattern items whose pairs are allowed (reason User).
        ongoing: ``"deepen"`` (default: a pair already in contact at the window start
            may not deepen beyond ``penetration_tol``; every other pair keeps the full
            margin, see :mod:`monitor.certify.ongoing`) or ``"violation"`` (plain
            certify: such a pair is a violation).
        penetration_tol: metres (default 5 mm), see ``ongoing``.
        action_shape: shape of the actions :meth:`decide` receives, against which an
            array ``fallback`` is checked (default ``(nu,)``: the action is the control).

    Settings reassigned after construction act from the next step, validated when assigned
    (``margin``, ``epsilon``, ``tolerances``, ``budget``, ``ongoing``, ``penetration_tol``,
    ``brake_horizon``, ``frame_skip``, ``reuse``, ``brake``, ``predictor``, ``on_violation``,
    ``unsafe``, ``fallback``, ``brake_vel_tol``; the reuse cache is keyed on what it depends on).
    Those that fix WHAT is certified and that the log records as the pair policy (``model``,
    ``pairs``, ``allowed``, ``hazards``, ``allow``; ``reference_qpos`` once the scene is built)
    raise InvalidInputError: construct a new Gate (:mod:`monitor.gate_settings`). The log's run
    metadata keeps ``predictor``, ``on_violation``, ``unsafe`` and ``frame_skip`` as they were when
    it was opened (each window records its own times, request and replacement).

    A gate whose model has no candidate pairs under ``pairs`` warns (``UserWarning``) once, at
    construction, since it checks nothing; the scene itself is built at the first decision
    (``allowed="auto"`` needs the first state as its reference pose), and then warns once more
    if the allowed-contact matrix left nothing.

    Raises:
        InvalidInputError: on an unknown option, a bad ``log``, ``fallback``, ``budget`` or
            ``tolerances``, negative margin or epsilon <= 0.
    """

    def __init__(self, model: mujoco.MjModel, *, pairs: Any = "mujoco", margin: float = 0.0,
                 epsilon: float = 1e-3, predictor: str | Callable[..., Any] = "rollout",
                 on_violation: str = "block", unsafe: str = "uncertain",
                 fallback: Any = None, budget: Any = None, log: Any = None, frame_skip: int = 1,
                 reuse: bool = True, brake: bool = True, brake_horizon: float = 0.25,
                 brake_vel_tol: float = 1e-3, tolerances: Tolerances = DEFAULT,
                 log_options: dict[str, Any] | None = None,
                 action_shape: tuple[int, ...] | None = None, allowed: Any = "auto", hazards: Any = None,
                 allow: Any = None, ongoing: str = "deepen",
                 penetration_tol: float = DEFAULT_PENETRATION_TOL) -> None:
        if not isinstance(model, mujoco.MjModel):
            raise InvalidInputError(f"Gate needs a mujoco.MjModel, got {type(model).__name__}")
        if on_violation not in ON_VIOLATION:
            raise InvalidInputError(f"on_violation must be one of {ON_VIOLATION}, got {on_violation!r}")
        if unsafe not in UNSAFE:
            raise InvalidInputError(f"unsafe must be one of {UNSAFE}, got {unsafe!r}")
        _check_predictor(predictor)
        _check_nstep(frame_skip, "frame_skip")
        _make_budget(budget)  # validate early
        self._margin, self._epsilon, self._tolerances = 0.0, 1e-3, DEFAULT  # set below (validated)
        _check_log(log)
        self._cache: dict[int, tuple[bytes, PairResult]] = {}
        self._cache_context: tuple[Any, ...] | None = None
        self._pair_bodies_cache: tuple[Any, ...] | None = None
        self._moving_memo: tuple[Any, ...] | None = None  # the last _pairs_moving call (see there)
        self._scene_builds = 0
        self._request: CertifyRequest | None = None  # built from the settings below on first use
        check_rule(ongoing, penetration_tol)  # validate both before either is set
        self.penetration_tol = penetration_tol
        self.ongoing = ongoing
        # fixed (gate_settings): what is certified and what the log records as the pair policy
        self._model, self._pairs = model, frozen_items(pairs)
        self._allowed, self._hazards = frozen_items(allowed), frozen_items(hazards)
        self._allow = frozen_items(allow)
        self.reference_qpos = None  # allowed="auto": Default's reference pose (validated property)
        self.margin = margin
        self.epsilon = epsilon
        self.predictor = predictor
        self.on_violation = on_violation
        self.unsafe = unsafe
        self._fallback_shape = (model.nu,) if action_shape is None else tuple(action_shape)
        self.fallback = fallback  # validated (property), as are the settings below
        self.budget = budget
        self.frame_skip = frame_skip
        self.reuse = bool(reuse)
        self.brake = bool(brake)
        self.brake_horizon = brake_horizon  # validated (property)
        self.brake_vel_tol = brake_vel_tol
        self._committed: np.ndarray | None = None
        self._joint_tail = True  # private: False forces today's two certify calls (the tests' oracle)
        self._joint_hint = True  # try the joint window + tail call (see decide)
        self._joint_witness: Any = None  # the last failed joint call's witness inside the tail, or None
        self._joint_of: tuple[np.ndarray, Any] | None = None  # with it: (the tail rows, the joint Plan)
        self._plain: tuple[CertifyRequest, CertifyRequest] | None = None  # (request, its plain copy)
        self._nothing_template: tuple[Any, ...] | None = None  # see _certify_nothing
        self._static_keys: tuple[Any, dict[bytes, dict[int, bytes]]] | None = None  # see _certify_static
        self._last_static: tuple[Any, dict[int, bytes]] | None = None  # (plan, keys): _split_reuse, all fixed
        self._call_request: CertifyRequest | None = None  # set during the joint call (see _certify)
        self._tail: tuple[Any, Certificate, np.ndarray] | None = None  # committed brake's certified tail
        self._log_accepted: int | None = None  # log index of the last accepted window (it commits a tail)
        self._tail_record: tuple[Certificate, int] | None = None  # (tail certificate, its log record index)
        self._noted_version: int | None = None  # scene version the log last compared the model at
        self._data_checked: Any = None  # weakref to the MjData whose sizes decide() last checked
        self._tail_context: tuple[Any, ...] | None = None  # settings + geometry the tail was certified under
        self._scene = None
        self.tolerances = tolerances
        self._rollout = Rollout(model)
        self._log_spec = log
        self._log_options = dict(log_options or {})
        if isinstance(log, (str, os.PathLike)):
            self._log_options["key"] = _log_key(self._log_options.get("key"))  # a bad key: here, not mid-run
        self._log = None
        self._log_owned = False
        self._log_lock: Any = None
        self._log_path: Path | None = None  # log_path (read-only property)
        self._predictor_label: str | None = None  # the log's "predictor" if an adapter predicts (SafetyGate)
        self.last_report: StepReport | None = None
        self.stats = {"windows": 0, "certified": 0, "violation": 0, "uncertain": 0, "replaced": 0,
                      "fallback_uncertified": 0, "brake_rejected": 0, "tail_reused": 0,
                      "tail_replay_differs": 0, "certify_us": 0.0, "reused_pairs": 0, "pairs": 0,
                      "committed": 0, "joint": 0, "tail_refuted": 0, "static_reused": 0,
                      "tail_ongoing_fresh": 0}
        self._warned = False
        if _no_candidate_pairs(model, self._pairs):  # cheap (no shapes): the scene is built at first use
            self._warned_empty = True
            where = self._log_options.get("env_id") or _model_name(model) or "the model"
            warnings.warn(
                f"monitor.Gate on {where}: no candidate pairs to check under pairs={pairs!r}, so every "
                "window is certified without checking anything (info['safety']['monitored_pairs'] == 0). "
                "Pass pairs='all' or a list of geom-name pairs to monitor.", UserWarning, stacklevel=2)

    # ----------------------------------------------------------------- settings (see monitor.gate_settings)
    model = fixed_setting("model", "the MjModel the scene, rollout and log are built on; edit it in place, "
                                   "the gate re-reads it every step")
    pairs = fixed_setting("pairs", "the scene's candidate pairs, recorded in the log's pair policy")
    allowed = fixed_setting("allowed", "the allowed-contact matrix, recorded in the log's pair policy")
    hazards = fixed_setting("hazards", "the pattern items selecting the checked pairs, recorded in the log")
    allow = fixed_setting("allow", "the pattern items of user-allowed pairs, recorded in the log")
    log_path = fixed_setting("log_path", "the file the gate writes: None until the first window, or when "
                                         "not logging to a path", arg="log")
    reference_qpos = checked_setting("reference_qpos", check_reference,
                                     "(nq,) pose ``allowed='auto'`` is resolved at (None: the first state); "
                                     "only before the scene is first built.")
    frame_skip = checked_setting("frame_skip", lambda g, v: _check_nstep(v, "frame_skip"),
                                 "Default substeps per window (an integer >= 1).")
    reuse = checked_setting("reuse", check_flag("reuse"), "Reuse results of fixed, unchanged pairs.")
    brake = checked_setting("brake", check_flag("brake"), "Recoverability check with a committed brake.")
    predictor = checked_setting("predictor", lambda g, v: _check_predictor(v),
                                "``\"rollout\"`` or a callable ``predictor(data, ctrl, nstep) -> Plan``.")
    on_violation = checked_setting("on_violation", check_choice("on_violation", ON_VIOLATION),
                                   "``\"block\" | \"terminate\" | \"warn\"``.")
    unsafe = checked_setting("unsafe", check_choice("unsafe", UNSAFE),
                             "``\"uncertain\"`` or ``\"violation\"``.")
    fallback = checked_setting("fallback", lambda g, v: _check_fallback(v, g._fallback_shape),
                               "None (hold position), an action array or a callable ``fallback(data)``; a "
                               "brake committed by the last accepted window stays in force until the next.")
    brake_vel_tol = checked_setting(
        "brake_vel_tol", lambda g, v: _finite_setting(v, "brake_vel_tol", positive=False, what=""),
        "The braking tail ends once every ``|qvel|`` is at most this (rad/s, m/s).")

    # ----------------------------------------------------------------- braking tail length
    @property
    def brake_horizon(self) -> float:
        """Longest braking tail (s of simulation time); reassignable (validated, used from the next step)."""
        return self._brake_horizon

    @brake_horizon.setter
    def brake_horizon(self, value: float) -> None:
        self._brake_horizon = _finite_setting(value, "brake_horizon", positive=True, what=" of seconds")

    @property
    def brake_steps(self) -> int:
        """Substeps of the longest braking tail: ``ceil(brake_horizon / model.opt.timestep)``, at least 1.

        Read from the live model on every use, so an edited ``opt.timestep`` (a dynamics edit) keeps
        the horizon in seconds (it was fixed at construction before 2026-11-28: a halved timestep
        halved the braking tail's simulated time; red team 4).
        """
        dt = float(self.model.opt.timestep)
        if not (math.isfinite(dt) and dt > 0.0):
            raise InvalidInputError(f"model.opt.timestep must be a finite number > 0, got {dt!r}")
        steps = self._brake_horizon / dt
        if not steps <= MAX_BRAKE_STEPS:  # the tail's buffers are sized by it (red team 5)
            raise InvalidInputError(
                f"brake_horizon {self._brake_horizon!r} s over model.opt.timestep {dt!r} s is {steps:.3g} "
                f"substeps per braking tail, more than MAX_BRAKE_STEPS = {MAX_BRAKE_STEPS}: shorten "
                "brake_horizon or raise monitor.gate.MAX_BRAKE_STEPS")
        return max(1, int(math.ceil(steps)))

    # ----------------------------------------------------------------- settings the cache depends on
    @property
    def margin(self) -> float:
        """Clearance (m) that counts as safe; reassignable (validated, the reuse cache is keyed on it)."""
        return self._margin

    @margin.setter
    def margin(self, value: float) -> None:
        if not _is_real(value) or not math.isfinite(float(value)) or value < 0:
            raise InvalidInputError(f"margin must be a finite number >= 0, got {value!r}")
        self._margin = float(value)
        self._request = None

    @property
    def epsilon(self) -> float:
        """Certification tolerance (m); reassignable (validated, the reuse cache is keyed on it)."""
        return self._epsilon

    @epsilon.setter
    def epsilon(self, value: float) -> None:
        if not _is_real(value) or not math.isfinite(float(value)) or value <= 0:
            raise InvalidInputError(f"epsilon must be a finite number > 0, got {value!r}")
        self._epsilon = float(value)
        self._request = None

    @property
    def tolerances(self) -> Tolerances:
        """Numerical tolerances; reassigning rebuilds the scene (built with them) and empties the cache."""
        return self._tolerances

    @tolerances.setter
    def tolerances(self, value: Tolerances) -> None:
        if not isinstance(value, Tolerances):
            raise InvalidInputError(f"tolerances must be a monitor.Tolerances, got {type(value).__name__}")
        self._tolerances = value
        self._scene = None
        self._request = None

    @property
    def budget(self) -> Any:
        """Work limits per window; reassignable (validated).

        None, seconds, tests, a dict or a Budget (its limits: a fresh clock per window).
        The limits are read once into :attr:`request` (at its first use after an assignment):
        to change them, assign again (editing a Budget object in place afterwards is not seen).
        """
        return self._budget

    @budget.setter
    def budget(self, value: Any) -> None:
        _make_budget(value)  # validate
        self._budget = value
        self._request = None

    @property
    def ongoing(self) -> str:
        """The ongoing-contact rule, ``"deepen"`` or ``"violation"``; reassignable (validated)."""
        return self._ongoing

    @ongoing.setter
    def ongoing(self, value: str) -> None:
        check_rule(value, DEFAULT_PENETRATION_TOL)
        self._ongoing = value
        self._request = None

    @property
    def penetration_tol(self) -> float:
        """Metres of penetration an ongoing contact may reach; reassignable (validated)."""
        return self._penetration_tol

    @penetration_tol.setter
    def penetration_tol(self, value: float) -> None:
        self._penetration_tol = check_rule("deepen", value)
        self._request = None

    @property
    def request(self) -> CertifyRequest:
        """The :class:`~monitor.certify.request.CertifyRequest` every window is certified with.

        Built once per setting (rebuilt after ``margin``, ``epsilon``, ``tolerances``,
        ``budget``, ``ongoing`` or ``penetration_tol`` is reassigned); window None (each
        window's plan span) and pairs None (all candidate pairs). Its budget is the limits of
        ``budget`` (a fresh clock per window, as before). The log stores it in its metadata.
        """
        req = self._request
        if req is None:
            b = _make_budget(self._budget)
            limits = BudgetLimits.of(None) if b is None else BudgetLimits(seconds=b.seconds, tests=b.tests)
            req = self._request = CertifyRequest(margin=self._margin, epsilon=self._epsilon, budget=limits,
                                                 tolerances=self._tolerances, ongoing=self._ongoing,
                                                 penetration_tol=self._penetration_tol)
        return req

    def _reuse_context(self) -> tuple[Any, ...]:
        """Everything a reused pair result depends on besides the two bodies' poses."""
        version = getattr(self.scene, "version", 0)
        return (self._margin, self._epsilon, self._tolerances, self._scene_builds, version, self.ongoing,
                self.penetration_tol)

    def _sync_scene(self) -> None:
        """Re-read the live model into the scene (``Scene.sync``, when the scene has it)."""
        sync = getattr(self.scene, "sync", None)
        if callable(sync):
            sync()

    # ----------------------------------------------------------------- scene / certify
    @property
    def scene(self) -> Any:
        """The :class:`monitor.Scene` (built on first use)."""
        if self._scene is None:
            from monitor.scene import Scene

            self._scene = Scene.from_model(self.model, pairs=self.pairs, tolerances=self.tolerances,
                                           allowed=self.allowed, hazards=self.hazards, allow=self.allow,
                                           reference=self.reference_qpos)
            self._scene_builds += 1
            announce(self)  # issue 13: say what is monitored; warn once when nothing is
        return self._scene

    def describe(self) -> str:
        """One line: pairs monitored, pairs allowed by reason, the ongoing-contact rule."""
        return describe_gate(self)

    @property
    def npairs(self) -> int:
        """Number of candidate pairs."""
        return len(self.scene.pair_ids)

    def predict(self, data: mujoco.MjData, ctrl: np.ndarray | None, nstep: int | None = None) -> Any:
        """The plan of the next window under ``ctrl`` (the configured predictor).

        Raises:
            InvalidInputError: ``nstep`` is not an integer in [1, :data:`MAX_WINDOW_STEPS`].
        """
        n = self.frame_skip if nstep is None else _check_nstep(nstep, "nstep")
        if callable(self.predictor):
            return self.predictor(data, ctrl, n)
        return self._rollout.plan(data, ctrl, n)

    def certify_plan(self, plan: Any) -> Certificate:
        """Certify an explicit plan (with pair reuse and the gate's budget) against the live model."""
        self._sync_scene()
        return self._certify(plan)[0]

    def _certify(self, plan: Any) -> tuple[Certificate, float]:
        """Certificate of ``plan`` and the wall time in µs.

        Under the gate's request, or ``self._call_request`` while that is set (the joint call's).
        """
        from monitor.certify.engine import certify

        t_start = time.perf_counter()
        scene = self.scene
        req = self._call_request or self._request or self.request
        todo, reused, keys = self._split_reuse(scene, plan)
        if todo is None:  # nothing reusable: one plain call
            cert = certify(scene, plan, request=req)
        else:
            cert = self._certify_subset(certify, scene, plan, todo, reused, req)
        if keys:  # fixed pairs (only with reuse on)
            self._remember(cert, keys)
        us = (time.perf_counter() - t_start) * 1e6
        self.stats["reused_pairs"] += len(reused)
        self.stats["pairs"] += _npairs(cert)
        return cert, us

    def _certify_is_own(self) -> bool:
        """Whether :meth:`_certify` is this module's own (not replaced on the instance or the class).

        :meth:`_certify_nothing` and :meth:`_certify_static` stand for its result; a replaced
        ``_certify`` (a test's stub checker or spy), or a replaced
        ``monitor.certify.engine.certify`` (which :meth:`_certify` calls), is called as before.
        """
        from monitor.certify import engine

        return ("_certify" not in self.__dict__ and type(self)._certify is _GATE_CERTIFY
                and engine.certify is engine._OWN_CERTIFY)

    def _rows_are_plan_qpos(self) -> bool:
        """Whether a window's Plan has its rows' qpos bit for bit and no mocap pose.

        True when the model has no ball / free joint (``nq == nv``: no quaternion the Plan
        normalises) and no mocap body (no mocap pose it normalises and validates).
        """
        m = self.model
        return m.nq == m.nv and not m.nmocap

    def _certify_nothing(self, win: _WindowRows) -> tuple[Certificate, float] | None:
        """:meth:`_certify` of the rollout's window when the scene has no candidate pair, without a Plan.

        ``certify`` of such a scene checks its arguments and returns its "nothing to check"
        certificate (``stats["nothing_checked"]``, 0 pairs, verdict ``"certified"``, the
        request's ``method``); this makes the same certificate from the window's rows (to_dict
        equal field for field but ``wall_seconds``; ``tests/test_gate_zero_pairs.py`` compares
        them) and the same request, without building the window's Plan. The Plan is built
        only when something reads it (a log, :attr:`StepReport.plan`).

        The input checks of the Plan and of ``certify`` stay: the window's times and qpos
        finite (their sum is: a NaN or inf entry makes it NaN or inf; a sum that overflows
        is declined too) and the times strictly increasing (so ``t1 > t0``). Anything else (a
        failed check, whose typed error and message the Plan gives; a model with ball / free
        joints or mocap bodies, whose quaternion norms and mocap poses the Plan validates; the
        joint call's request) returns None: the caller certifies the Plan as before. The scene
        is the gate's own, synced by :meth:`decide`, and the rows come from the live model, so
        ``certify``'s model checks hold by construction.
        :meth:`decide` uses it only where :meth:`_certify_is_own`.

        Args:
            win: the window's rows (:meth:`Rollout._window`).

        Returns:
            (certificate, µs) or None.
        """
        t_start = time.perf_counter()
        if not self._rows_are_plan_qpos() or self._call_request is not None:
            return None  # quaternions or mocap poses to validate, or a joint call
        rows = win.rows
        if not math.isfinite(float(rows.sum())):  # a NaN / inf time or qpos (or a sum that overflows)
            return None  # the Plan raises with its message
        times = rows[:, 0].tolist()
        if not all(a < b for a, b in zip(times, times[1:])):
            return None  # not strictly increasing: the Plan raises with its message
        req = self.request
        allowed = self.scene.allowed_pairs
        hit = self._nothing_template
        if hit is None or hit[0] is not req or hit[1] is not allowed:
            # built by the constructor once per (request, allowed pairs); each window gets a copy
            template = Certificate(Verdict.CERTIFIED, (0.0, 0.0), req.margin, req.epsilon, req.method.value,
                                   None, None, math.inf, (), {},
                                   allowed if type(allowed) is tuple else tuple(allowed))
            template.__dict__["request"] = req
            hit = self._nothing_template = (req, allowed, template)
        cert = object.__new__(Certificate)  # = copy.copy(template): a dataclass's state is its __dict__
        state = cert.__dict__
        state.update(hit[2].__dict__)
        state["window"] = (times[0], times[-1])  # Python floats, as the Plan's t0 / t1
        state["stats"] = nothing_checked_stats(time.perf_counter() - t_start)
        return cert, (time.perf_counter() - t_start) * 1e6

    def _certify_static(self, win: _WindowRows) -> tuple[Certificate, float] | None:
        """:meth:`_certify` of a window in which no body moves, answered from the reuse cache without a Plan.

        :meth:`_split_reuse` keys each fixed pair's cached result on the bytes of its two
        bodies' poses at t0, computed by the window Plan's forward kinematics. Those poses
        are a function of the Plan's qpos rows and the model's kinematic structure only (no
        mocap body here; t0 is the first waypoint). So :meth:`_remember_static` keeps, for a
        window of the gate's own rollout in which every pair was fixed, its keys under the
        bytes of its qpos rows (on a model without ball / free joints and mocap bodies those
        are the Plan's qpos, bit for bit), within one reuse context (settings, scene builds,
        scene version; the Plan's structure fields are among the scene's watched fields,
        ``tests/test_engine_entry.py``, so an edit of them bumps the version). A later window
        with the same qpos bytes in the same context has the same keys: this looks them up
        instead of building the Plan and its poses, then does what :meth:`_certify` does
        when every pair is reused (the same cache reads, merged certificate, cache writes
        and counters). Anything else returns None (the caller runs :meth:`_certify`): no
        memo for these rows, another context (:meth:`_certify` empties the cache), or a
        pair whose cached result does not match (it must be certified). :meth:`decide` uses
        it only where :meth:`_certify_is_own`.

        Args:
            win: the window's rows (:meth:`Rollout._window`).

        Returns:
            (certificate, µs) or None.
        """
        t_start = time.perf_counter()
        memo = self._static_keys
        if memo is None or not self.reuse or self._call_request is not None:
            return None
        self._sync_scene()  # a fallback callable may have edited the model since decide's sync (red team 6)
        context = self._reuse_context()
        if memo[0] != context or context != self._cache_context:
            return None
        keys = memo[1].get(win.rows[:, 1:].tobytes())
        scene = self.scene
        if keys is None or len(keys) != len(scene.pair_ids):
            return None
        cache = self._cache
        reused = {}
        for i, key in keys.items():
            hit = cache.get(i)
            if hit is None or hit[0] != key:
                return None
            reused[i] = hit[1]
        cert = self._certify_subset(None, scene, win, [], reused)  # type: ignore[arg-type]  # nothing to certify
        self._remember(cert, keys)
        us = (time.perf_counter() - t_start) * 1e6
        self.stats["reused_pairs"] += len(reused)
        self.stats["pairs"] += _npairs(cert)
        self.stats["static_reused"] += 1
        return cert, us

    def _remember_static(self, win: _WindowRows, plan: Any) -> None:
        """After :meth:`_certify` of ``plan`` (``win.plan``): keep its pose keys for :meth:`_certify_static`.

        Only when every pair was fixed in it (:meth:`_split_reuse` saw the same plan object)
        and the model has no ball / free joint and no mocap body (the Plan's qpos are the
        rows' own bytes).
        """
        last, self._last_static = self._last_static, None
        if last is None or last[0] is not plan or not self._rows_are_plan_qpos():
            return
        context = self._cache_context
        memo = self._static_keys
        if memo is None or memo[0] != context or len(memo[1]) >= 64:
            memo = self._static_keys = (context, {})
        memo[1][win.rows[:, 1:].tobytes()] = last[1]

    def _certify_joint(self, plan: Any, window_rows: np.ndarray | None, tail_rows: np.ndarray,
                       mocap_pos: np.ndarray, mocap_quat: np.ndarray
                       ) -> tuple[Certificate, Certificate, float] | None:
        """Certify the window and its braking tail with ONE call; None unless that settles both.

        Args:
            plan: the window's Plan, built from ``window_rows``.
            window_rows: (n + 1, 1 + nq) rows (time, qpos) ``plan`` was built from
                (:attr:`Rollout.window_rows`), or None.
            tail_rows: (K, 1 + nq) rows (time, qpos) of the braking tail (the tail's Plan would
                be built from them).
            mocap_pos, mocap_quat: (nmocap, 3), (nmocap, 4) mocap poses held over both parts (the
                live data's, as both parts' Plans got them).

        The joint plan is built from the window's rows followed by the tail's (the tail starts
        at the window's last row, checked bit for bit), so each waypoint is normalised exactly
        as in the window's or the tail's own Plan. Plans interpolate piecewise between
        consecutive waypoints, so the joint plan's motion on [t0, t1] is the window's and on
        [t1, t_end] the tail's, exactly.

        When is one call as strong as two? A certificate of the joint plan bounds the
        clearance over [t0, t_end], hence over each part. Under ``ongoing="violation"`` that
        is all. Under ``ongoing="deepen"`` a pair judged by the ongoing-contact rule would be
        judged against its depth at t0, while the separate tail call judges it against its
        depth at the window's end t1 (and a pair clear at t1 keeps the full margin there):
        the joint call could be weaker. So the joint result is used only when it is
        ``certified`` and no freshly certified pair went through the rule
        (``stats["ongoing"]`` absent or 0): then every fresh pair has clearance > margin over
        [t0, t_end], which the two separate calls would accept under either rule (the rule
        only re-judges pairs the plain check did not certify). Pairs answered from the reuse
        cache are fixed over the whole joint window at unchanged poses, so their result is
        the same for the window, the tail and the joint plan.

        Anything else (uncertain, violation, an ongoing contact, a plan that does not join)
        returns None and the caller runs today's two calls, so verdicts and witnesses of
        those windows are exactly today's. One exception, for the tail only: a joint
        ``violation`` whose witness lies in the tail's span [t1, t_end] (and no ongoing pair)
        is kept in ``self._joint_witness``; :meth:`_tail_refuted` may then reject the tail
        without certifying it again (the brake decision is the one the tail's own call gives).

        Returns:
            (window certificate, tail certificate, µs) or None. The two certificates are the
            joint one with ``window`` set to the part's span (its clearance, a lower bound
            over [t0, t_end], bounds each part too) and ``stats["joint_window"] = [t0, t_end]``.
        """
        from monitor.motion.plan import Plan

        self._joint_witness = self._joint_of = None
        # Bit-for-bit checks (bytes: stricter than ==, e.g. -0.0 != 0.0); both hold by
        # construction on the gate's own path, a failure only means two calls.
        if (window_rows is None or len(tail_rows) < 2 or window_rows.shape[1] != tail_rows.shape[1]
                or not ((isinstance(plan, _WindowRows) and plan.rows is window_rows)  # the same rows
                        or window_rows[:, 0].tobytes() == np.asarray(plan.times).tobytes())
                or window_rows[-1].tobytes() != tail_rows[0].tobytes()):
            return None
        # times (K,) and qpos (K, nq): fresh C-contiguous arrays, the values of the rows
        # concatenated (window, then the tail after its first row)
        times = np.concatenate((window_rows[:, 0], tail_rows[1:, 0]))
        qpos = np.concatenate((window_rows[:, 1:], tail_rows[1:, 1:]))
        joint = Plan._trusted(times, qpos, model=self.model, mocap_pos=mocap_pos.copy(),
                              mocap_quat=mocap_quat.copy())
        self._call_request = self._plain_request()
        try:
            cert, us = self._certify(joint)
        finally:
            self._call_request = None
        if not cert.certified or cert.stats.get("ongoing", 0):
            w = cert.witness
            if (cert.verdict == Verdict.VIOLATION and not cert.stats.get("ongoing", 0) and w is not None
                    and float(tail_rows[0, 0]) <= w.time <= float(times[-1])):
                self._joint_witness = w  # a confirmed violation inside the tail (see _tail_refuted)
                self._joint_of = (tail_rows, joint)
            return None
        cert.__dict__["request"] = self.request  # (not a compared field) what a call under it returns
        self.stats["joint"] += 1
        t0, t1, t_end = float(times[0]), float(tail_rows[0, 0]), float(times[-1])
        span = [t0, t_end]
        return _part(cert, (t0, t1), span), _part(cert, (t1, t_end), span), us

    def _plain_request(self) -> CertifyRequest:
        """The gate's request under ``ongoing="violation"`` (the joint call's; cached per request).

        The joint call's certificate is used only when it is ``certified`` with no ongoing
        pair (:meth:`_certify_joint`). Under ``"deepen"``, ``certify`` returns a certified
        plain certificate unchanged, and re-judges the pairs of any other one: the result is
        then either not certified or certified through the ongoing rule (``stats["ongoing"]``),
        and the gate uses neither. So the joint call skips the rule (issue 12: on the Arm
        it cost ~40 % of the failing joint calls): the same windows are settled by it, with the
        same certificates (the gate's request is set on them), and the rest fall back as before.
        A witness of the plain call is still a confirmed violation (:meth:`_tail_refuted`
        checks the ongoing rule at the TAIL's start, the only one the tail's call applies).
        """
        req = self.request
        if req.ongoing == "violation":
            return req
        hit = self._plain
        if hit is None or hit[0] is not req:
            hit = self._plain = (req, req.replace(ongoing="violation"))
        return hit[1]

    def _tail_refuted(self, witness: Any, tail: _Tail) -> bool:
        """Whether the joint call's ``witness`` decides the tail as its own certify call would.

        Args:
            witness: the :class:`Witness` of a ``violation`` of the joint plan (window + tail,
                no ongoing pair) at a time in the tail's span [t1, t_end]
                (:meth:`_certify_joint` keeps it in ``self._joint_witness``).
            tail: the braking tail whose certificate the caller is about to compute.

        The witness is a confirmed violation of the continuous motion: the exact static
        distance of its pair at ``witness.time`` is below the margin (rounding padded up).
        On [t1, t_end] the joint plan's motion is the tail plan's, exactly (same rows,
        same interpolation: :meth:`_certify_joint`), so the tail's motion has that
        configuration too, and a sound certificate of the tail can only say ``violation``
        or ``uncertain`` for that pair, hence for the tail, unless the tail's call re-judges
        the pair by the ongoing-contact rule. Under ``ongoing="deepen"`` it does that only
        for a pair whose static lower bound at the tail's start is <= margin
        (:func:`monitor.certify.ongoing.deepen`): the same ``shape_distance`` on the same
        poses (the tail plan's at t1) is computed here, and the pair must be clear. Then
        every verdict the tail's call could give is unsafe under ``unsafe="uncertain"``
        (the default: anything not certified), which is the only policy this answers for:
        under ``unsafe="violation"`` an ``uncertain`` tail is accepted, so the tail is
        certified as before. The brake is rejected exactly when the tail's own call would
        reject it; the reported ``brake_verdict`` is ``"violation"`` (the tail's call could
        only differ by saying ``"uncertain"``).

        Returns:
            True when the tail can be rejected without its own certify call.
        """
        if self.unsafe != "uncertain":
            return False
        if self.ongoing != "violation":   # "deepen": the pair must not be ongoing at the tail's start
            from monitor.certify.ongoing import start_distance

            scene = self.scene
            try:
                ga, gb = scene.geom(witness.geoms[0]), scene.geom(witness.geoms[1])
            except InvalidInputError:   # not a geom of the scene (cannot happen on the gate's path)
                return False
            poses = self._joint_poses_at_tail_start(tail)
            if poses is None:
                plan = tail.plan
                poses = plan.body_poses(np.array([float(plan.times[0])]))
            dist = start_distance(ga, gb, poses, self.tolerances)
            if not dist.lower > self.margin:
                return False
        return True

    def _joint_poses_at_tail_start(self, tail: _Tail) -> tuple[np.ndarray, np.ndarray] | None:
        """``tail.plan.body_poses([t1])`` from the failed joint call's Plan, or None.

        Only for the tail whose rows that joint Plan was built from (the same array object, see
        :meth:`_certify_joint`) and a model without ball / free joints (``nq == nv``). Then the
        two are the same floats: the joint Plan's waypoints are the window's rows followed by
        the tail's after its first row, and the window's last row is the tail's first, bit for
        bit (checked by :meth:`_certify_joint`); at t1, a waypoint of both, each Plan locates
        the segment that starts there with local parameter ``(t1 - t1) / dt = 0.0`` and
        interpolates ``q[i] + 0.0 * (q[i + 1] - q[i])`` on the same two rows (the tail's first
        two), so the same qpos (no quaternion track: lerp only); held mocap poses are
        normalised from copies of the same arrays with the same default tolerances; FK is
        ``mj_kinematics`` on the same model. The tail's own Plan (a 100+ waypoint build on the
        Arm) is then not needed.
        """
        hit = self._joint_of
        m = self.model
        if hit is None or hit[0] is not tail.rows or m.nq != m.nv:
            return None
        return hit[1].body_poses(np.array([float(tail.rows[0, 0])]))

    def _split_reuse(self, scene: Any, plan: Any) -> tuple[list[int] | None, dict[int, PairResult],
                                                             dict[int, bytes]]:
        """Indices of pairs to certify (None = all), reusable results, cache keys of fixed pairs."""
        if not self.reuse:
            return None, {}, {}
        moving = np.asarray(plan.moving_bodies(), bool)
        body_a, body_b = self._pair_bodies(scene)
        either, all_move = self._pairs_moving(moving, body_a, body_b)
        if all_move:  # every pair has a moving body (the common gated step): nothing to reuse
            return None, {}, {}  # (the cache is neither read nor written: its context is checked below)
        # User code (a fallback, cast or predict callable) may have edited the model since decide's
        # sync: the context must name the live geometry, and the pairs above the live pairs (red team 6).
        version = getattr(scene, "version", 0)
        self._sync_scene()
        if getattr(scene, "version", 0) != version:
            return self._split_reuse(scene, plan)  # rebuilt: split again over the new pairs
        context = self._reuse_context()
        if context != self._cache_context:  # before any read or write of the cache
            self._cache.clear()
            self._cache_context = context
        fixed = np.flatnonzero(~either)
        pos, rot = plan.body_poses(np.array([plan.t0]))
        ba, bb = body_a[fixed], body_b[fixed]
        # key of pair i: the bytes of (p_a (3,), R_a (9,), p_b (3,), R_b (9,)) at t0
        rows = np.concatenate([pos[0, ba], rot[0, ba].reshape(-1, 9), pos[0, bb], rot[0, bb].reshape(-1, 9)],
                              axis=1)
        keys, reused = {}, {}
        cache = self._cache
        for i, row in zip(fixed.tolist(), rows):
            key = row.tobytes()
            keys[i] = key
            hit = cache.get(i)
            if hit is not None and hit[0] == key:
                reused[i] = hit[1]
        if len(fixed) == len(body_a):  # every pair fixed: _remember_static may keep these keys
            self._last_static = (plan, keys)
        if not reused:
            return None, {}, keys
        todo = [i for i in range(len(body_a)) if i not in reused]
        return todo, reused, keys

    def _pairs_moving(self, moving: np.ndarray, body_a: np.ndarray, body_b: np.ndarray
                      ) -> tuple[np.ndarray, bool]:
        """``(either, either.all())``: (P,) bool ``moving[body_a] | moving[body_b]`` (a pair body moves).

        Memoised on the last call: a pure function of the bytes of ``moving`` ((nbody,) bool) and
        of the two (P,) body-id arrays, which are :meth:`_pair_bodies`' cached arrays (never
        written; new objects after a scene rebuild, so they are compared by identity, and the memo's
        references keep them alive). Consecutive windows of one episode usually move the same
        bodies: the four numpy calls (~2 µs) become one ``tobytes``. ``either`` is read-only.
        """
        key = moving.tobytes()
        memo = self._moving_memo
        if memo is not None and memo[0] is body_a and memo[1] is body_b and memo[2] == key:
            return memo[3], memo[4]
        either = moving[body_a]  # (P,) a body of the pair moves
        either |= moving[body_b]
        either.setflags(write=False)
        all_move = bool(either.all())
        self._moving_memo = (body_a, body_b, key, either, all_move)
        return either, all_move

    def _pair_bodies(self, scene: Any) -> tuple[np.ndarray, np.ndarray]:
        """(P,) body ids of each candidate pair's two geoms, cached per scene geometry.

        Keyed on the scene object and its current ``geoms`` / ``pair_ids`` objects, which
        ``Scene.sync()`` replaces on a rebuild.
        """
        hit = self._pair_bodies_cache
        if hit is not None and hit[0] is scene and hit[1] is scene.geoms and hit[2] is scene.pair_ids:
            return hit[3], hit[4]
        ids = np.asarray(scene.pair_ids, dtype=np.int64).reshape(-1, 2)
        body_of = np.array([g.body_id for g in scene.geoms], dtype=np.int64)
        body_a, body_b = body_of[ids[:, 0]], body_of[ids[:, 1]]
        self._pair_bodies_cache = (scene, scene.geoms, scene.pair_ids, body_a, body_b)
        return body_a, body_b

    def _certify_subset(self, certify: Callable[..., Certificate], scene: Any, plan: Any,
                        todo: list[int], reused: dict[int, PairResult],
                        request: CertifyRequest | None = None) -> Certificate:
        """Certify only ``todo`` and merge in the reused pair results (scene order).

        ``request``: the request of the fresh pairs (default the gate's); the merged
        certificate carries the gate's.
        """
        t0, t1 = float(plan.t0), float(plan.t1)
        if todo:
            names = tuple(tuple(scene.candidate_pairs[i]) for i in todo)
            fresh = certify(scene, plan, request=(request or self.request)._with_pairs(names))
            by_geoms = {p.geoms: p for p in fresh.pairs}
            fresh_pairs = [by_geoms[tuple(scene.candidate_pairs[i])] for i in todo]
        else:
            fresh = None
            fresh_pairs = []
        results: dict[int, PairResult] = dict(zip(todo, fresh_pairs))
        results.update(reused)
        pairs = tuple(results[i] for i in range(len(scene.pair_ids)))
        verdict = combine_verdicts([p.verdict for p in pairs])
        clearance = min((p.clearance for p in pairs), default=math.inf)
        stats = dict(fresh.stats) if fresh is not None else {}
        stats["reused_pairs"] = len(reused)
        stats["pairs"] = len(pairs)
        if fresh is None:
            merged = Certificate(verdict, (t0, t1), self.margin, self.epsilon, Method.AUTO, None, None,
                                 clearance, pairs, stats, scene.allowed_pairs)
        else:
            merged = Certificate(verdict, fresh.window, fresh.margin, fresh.epsilon, fresh.method,
                                 fresh.witness, fresh.earliest_time, min(clearance, fresh.clearance), pairs,
                                 stats, scene.allowed_pairs)
        merged.__dict__["request"] = self.request  # all pairs (reused + fresh): the gate's request
        return merged

    def _remember(self, cert: Certificate, keys: dict[int, bytes]) -> None:
        for i, key in keys.items():
            p = cert.pairs[i]
            if p.verdict == Verdict.CERTIFIED:
                self._cache[i] = (key, p)
            else:
                self._cache.pop(i, None)

    # ----------------------------------------------------------------- decisions
    def is_unsafe(self, verdict: str) -> bool:
        """Whether ``verdict`` counts as unsafe under the gate's ``unsafe=`` policy."""
        if self.unsafe == "violation":
            return verdict == Verdict.VIOLATION
        return verdict != Verdict.CERTIFIED

    def fallback_ctrl(self, data: mujoco.MjData) -> np.ndarray:
        """The fallback control for the current state (see ``fallback=``)."""
        fb = self.fallback
        if fb is None:
            return hold_ctrl(self.model, data)
        if callable(fb):
            return _check_fallback(fb(data), self._fallback_shape)  # typed error on a bad return value
        return np.asarray(fb, dtype=np.float64)

    def reset(self) -> None:
        """Forget the committed brake; the log starts a new episode (call when the state is reset)."""
        self._committed = None
        self._tail = None
        self._joint_hint = True  # a step's reports depend on its episode only, not on the last one
        if self._log is not None and not getattr(self._log, "closed", False):
            new_episode = getattr(self._log, "new_episode", None)
            if callable(new_episode):
                new_episode()

    def _tail_covers(self, data: mujoco.MjData, n: int) -> Certificate | None:
        """The committed tail's certificate if it contains the next ``n`` substeps.

        That is the case when the live state equals a tail waypoint bit for bit
        (time, qpos, qvel, mocap), the window ends inside the tail, margin, epsilon,
        tolerances and the scene version are those the tail was certified under, and
        the window of the committed brake, integrated now from the live data with the
        live model (:meth:`Rollout._window`), gives the tail's next ``n`` rows (time,
        qpos) bit for bit. The replay is what makes the reuse sound: a state equal to a
        tail waypoint does not imply the same motion after an in-place edit of the
        dynamics (``opt.gravity``, ``opt.timestep``, gains, masses, damping: none is in
        the scene version). It leaves the scratch holding the applied window, so the
        caller commits it instead of stepping again. Else None.
        """
        if self._tail is None:
            return None
        self._sync_scene()  # the context compared below must name the live geometry (red team 6)
        if self._tail_context != self._reuse_context():
            return None  # no tail, or certified under other settings / geometry
        tail, cert, qvel = self._tail
        if not cert.certified:
            return None
        # The tail Plan's times, qpos row and held mocap poses, read without building the
        # Plan where they are the rows' bit for bit (_Tail.plan_qpos_row / plan_mocap_quat;
        # times: the Plan's are a copy of rows[:, 0]; mocap_pos: a copy of tail.mocap_pos).
        times = tail.rows[:, 0]
        hits = np.flatnonzero(times == data.time)
        if len(hits) != 1:
            return None
        k = int(hits[0])
        # bit for bit: bytes (stricter than ==: -0.0 != 0.0); shapes are the model's, fixed
        if (k + n >= len(times) or tail.plan_qpos_row(k).tobytes() != data.qpos.tobytes()
                or qvel[k].tobytes() != data.qvel.tobytes()
                or tail.mocap_pos.tobytes() != data.mocap_pos.tobytes()
                or tail.plan_mocap_quat().tobytes() != data.mocap_quat.tobytes()):
            return None
        if k and cert.stats.get("ongoing", 0):
            # The tail's certificate judged its ongoing pairs (in contact at the TAIL's start) by the
            # ongoing rule over the whole tail: such a pair may lift off and touch again inside it.
            # Judged on this window alone, a pair clear at waypoint k that touches again is a new
            # contact (a violation), and an apart one may close by less. So past the tail's start a
            # window of a tail with ongoing pairs is certified afresh, under the same committed
            # brake (red team 18: 16 re-contacts reported certified in 12,891 audited steps).
            # At k = 0 the window starts where the tail does: the tail's verdict holds for it.
            self.stats["tail_ongoing_fresh"] += 1
            return None
        # replay: the brake's window under the live model must be the certified tail's rows
        rows = self._rollout._window(data, self._committed, n)
        if rows[1:].tobytes() != np.ascontiguousarray(tail.rows[k + 1:k + n + 1]).tobytes():
            self.stats["tail_replay_differs"] += 1
            return None
        return cert

    def _brake_active(self, fallback: Callable[[], Any] | None) -> bool:
        return (self.brake and self.on_violation != "warn" and fallback is None
                and not callable(self.fallback))

    def _brake_ctrl(self, d: mujoco.MjData) -> np.ndarray:
        return hold_ctrl(self.model, d) if self.fallback is None else np.asarray(self.fallback, float)

    def decide(self, data: mujoco.MjData, ctrl: Any, *, nstep: int | None = None,
               predict: Callable[[Any], Any] | None = None,
               fallback: Callable[[], Any] | None = None,
               cast: Callable[[Any], np.ndarray] | None = None) -> StepReport:
        """Certify the proposed window and pick the control to apply; does NOT step.

        This is the whole gating logic; :meth:`step` and :class:`monitor.SafetyGate`
        only add the stepping.

        Args:
            data: the live ``MjData`` (read only).
            ctrl: proposed control / action.
            nstep: substeps in the window (default ``frame_skip``).
            predict: optional ``predict(action) -> Plan`` replacing the gate's predictor
                (used by adapters whose action is not ``data.ctrl``).
            fallback: optional zero-argument callable giving the fallback action
                (default: the committed brake, else :meth:`fallback_ctrl`).
            cast: optional map applied to gate-made controls (fallback, brake) before
                they are predicted and applied, e.g. to the env's action dtype.

        Returns:
            the :class:`StepReport` (``stepped=False``).
        """
        n = self.frame_skip if nstep is None else _check_nstep(nstep, "nstep")
        ctrl = np.asarray(ctrl)
        if self._data_checked is None or self._data_checked() is not data:  # checked once per MjData
            _check_data(self.model, data)
            # ... of the gate's own model: data of an equal copy is compared again every step (that
            # copy may be edited in place later, e.g. a pickled gate stepping the original's data)
            self._data_checked = weakref.ref(data) if getattr(data, "model", None) is self.model else None
        _check_ctrl(ctrl, self._fallback_shape)
        if self._scene_builds == 0 and self._reference_qpos is None:  # issue 13: first state = ACM reference
            # (before the scene is first built: `allowed="auto"` frees the pairs touching at THIS pose)
            self._reference_qpos = np.array(data.qpos)
        self._sync_scene()  # certify against the model as it is now (domain randomisation, tuning)
        # user code in `cast` runs between the window's rollout and the note below: note before it
        user_cast = cast is not None and not getattr(cast, "_model_untouched", False)
        if user_cast:
            self._note_model()
        if cast is None:
            def cast(c: Any) -> np.ndarray:
                return np.asarray(c, dtype=np.float64)
        # the rollout's window (not a callable predictor, an adapter's, or an overridden Gate.predict)
        own_predictor = (predict is None and not callable(self.predictor)
                         and type(self).predict is Gate.predict)
        if predict is None:
            def predict(c: Any) -> Any:
                return self.predict(data, c, n)
        t_win = float(data.time)
        if own_predictor:  # the rollout's window; its Plan is built only when something reads it
            # (arguments left to right: window_key is read after _window set it)
            plan: Any = _WindowRows(self._rollout._window(data, ctrl, n), self.model, data,
                                    self._rollout.window_key)
        else:
            plan = predict(ctrl)
        brake_on = self._brake_active(fallback)
        tail = joint = joint_witness = None
        if (brake_on and self._joint_tail and self._joint_hint and own_predictor
                and self.scene.candidate_pairs):
            # Common path: window + braking tail certified by ONE call (see _certify_joint).
            rows, brake_next = self._rollout.brake_rows(
                data, ctrl, n, lambda d: cast(self._brake_ctrl(d)), self.brake_steps, self.brake_vel_tol,
                window_fresh=True)  # states() ran just above on this data, ctrl and n
            self._rollout.check_tail()
            tail = _Tail(rows, self.model, data, (self._rollout.window_key, brake_next))
            tail_qvel = tail.qvel
            joint = self._certify_joint(plan, self._rollout.window_rows, tail.rows, tail.mocap_pos,
                                        tail.mocap_quat)
            joint_witness = self._joint_witness
        if joint is not None:
            cert, tail_cert, us = joint
            unsafe, brake_verdict = False, tail_cert.verdict  # "certified"
        else:  # today's two calls (also after a joint call that did not certify)
            nothing = (self._certify_nothing(plan) if own_predictor and not self.scene.candidate_pairs
                       and self._certify_is_own() else None)  # no pair: _certify's own trivial certificate
            cert, us = nothing if nothing is not None else self._certify(_plan_of(plan))
            unsafe = self.is_unsafe(cert.verdict)
            brake_verdict = ""
            if tail is None:
                brake_next = None
            if not unsafe and brake_on and not self.scene.candidate_pairs:
                # No candidate pairs: every window (the tail's too) certifies trivially and
                # no proposal can ever be rejected, so the tail and its brake are never used.
                brake_verdict = Verdict.CERTIFIED
            elif not unsafe and brake_on:
                version = None
                if tail is None:  # raw rows kept: a committed tail is replayed against them (_tail_covers)
                    version = getattr(self.scene, "version", 0)  # the proposal was certified on it
                    rows, brake_next = self._rollout.brake_rows(
                        data, ctrl, n, lambda d: cast(self._brake_ctrl(d)), self.brake_steps,
                        self.brake_vel_tol)
                    self._rollout.check_tail()
                    tail = _Tail(rows, self.model, data, (self._rollout.window_key, brake_next))
                    tail_qvel = tail.qvel
                if joint_witness is not None and self._tail_refuted(joint_witness, tail):
                    # the joint call confirmed a violation inside the tail (see _tail_refuted)
                    tail_cert = None
                    brake_verdict = Verdict.VIOLATION
                    self.stats["tail_refuted"] += 1
                else:
                    tail_cert, tail_us = self._certify(tail.plan)
                    us += tail_us
                    brake_verdict = tail_cert.verdict
                if self.is_unsafe(brake_verdict):
                    unsafe = True
                    self.stats["brake_rejected"] += 1
                elif version is not None and getattr(self.scene, "version", 0) != version:
                    # ``cast`` (user code, called while the tail was rolled out) edited the model after
                    # the proposal was certified (red team 7): certify it again on the model as it is
                    cert, p_us = self._certify(_plan_of(plan))
                    us += p_us
                    unsafe = self.is_unsafe(cert.verdict)
            # Try the joint call next step only when this step's two calls would have allowed it
            # (both certified, no ongoing contact): a streak of rejected or in-contact windows
            # then costs two calls per step, not three.
            self._joint_hint = bool(cert.certified and not cert.stats.get("ongoing", 0)
                                    and tail is not None and brake_verdict == Verdict.CERTIFIED
                                    and not tail_cert.stats.get("ongoing", 0))
        if self._note_model() and user_cast:  # `cast` edited the model after the rollout (red team 7):
            _not_replayable(plan, tail)  # the rows are not the logged model's re-simulation
        applied, replaced, terminated = ctrl, False, False
        fb_cert, fb_ok, applied_verdict = None, True, cert.verdict
        applied_plan = plan
        if unsafe and self.on_violation != "warn":
            if fallback is not None:
                applied = np.asarray(fallback())
            elif self._brake_active(None) and self._committed is not None:
                applied = self._committed
            else:
                applied = cast(self.fallback_ctrl(data))
            replaced, terminated = True, self.on_violation == "terminate"
            covered = (self._tail_covers(data, n) if fallback is None and applied is self._committed
                       else None)
            if covered is not None:  # this window is part of the committed, certified tail
                fb_cert = covered
                applied_plan = None
                self.stats["tail_reused"] += 1
            elif own_predictor and self._certify_is_own():
                # the rows of predict(applied); the Plan built only when the cache cannot answer
                win = _WindowRows(self._rollout._window(data, applied, n), self.model, data,
                                  self._rollout.window_key)
                got = self._certify_static(win)  # a window with nothing moving: from the cache, no Plan
                if got is None:
                    got = self._certify(win.plan)
                    self._remember_static(win, win.plan)
                applied_plan = win
                fb_cert, fb_us = got
                us += fb_us
            else:
                applied_plan = predict(applied)
                fb_cert, fb_us = self._certify(applied_plan)
                us += fb_us
            applied_verdict = fb_cert.verdict
            fb_ok = fb_cert.verdict == Verdict.CERTIFIED
            if not fb_ok:
                self.stats["fallback_uncertified"] += 1
                (_LOG.debug if self._warned else _LOG.warning)(
                    "t=%.6f s: fallback window is %s (proposal was %s)%s", t_win, fb_cert.verdict,
                    cert.verdict, "" if self._warned else "; further cases are logged at DEBUG level")
                self._warned = True
        elif not unsafe:
            self._committed = brake_next
            self._tail = None if brake_next is None else (tail, tail_cert, tail_qvel)
            self._tail_context = self._reuse_context()
        report = StepReport._trusted(cert.verdict, cert, ctrl, applied, replaced, terminated, unsafe,
                                     applied_verdict, fb_cert, fb_ok, us, t_win, plan, brake_verdict)
        self._account(report)
        self._write_log(report, applied_plan, plan)
        self.last_report = report
        return report

    def step(self, data: mujoco.MjData, ctrl: Any, nstep: int | None = None) -> StepReport:
        """Certify the window of ``ctrl``; then step ``data`` with the applied control.

        ``data.ctrl`` is set to the applied control (the proposal, or the fallback
        when blocked) and ``mj_step`` runs ``nstep`` times, as gymnasium's
        ``MujocoEnv.do_simulation`` does. When the gate's scratch already integrated
        exactly that window (the usual case), its end state is copied instead
        (:meth:`Rollout.commit`; bit-identical, the simulation runs once per window).

        Args:
            data: the caller's ``MjData`` (advanced in place).
            ctrl: (nu,) proposed control.
            nstep: substeps (default ``frame_skip``).

        Returns:
            the :class:`StepReport` (``stepped=True``).
        """
        n = self.frame_skip if nstep is None else _check_nstep(nstep, "nstep")
        try:
            ctrl = np.asarray(ctrl, dtype=np.float64)
        except (TypeError, ValueError) as e:
            raise InvalidInputError(
                f"ctrl must be a numeric array of shape ({self.model.nu},), got {ctrl!r}") from e
        if ctrl.shape != (self.model.nu,):
            raise InvalidInputError(f"ctrl must have shape ({self.model.nu},), got {ctrl.shape}")
        report = self.decide(data, ctrl, nstep=n)  # (NaN / inf refused there)
        # The scratch usually holds the applied window already (the proposal's, or the
        # fallback's when it was predicted): copy it instead of integrating again (exact,
        # see Rollout.commit). Otherwise (a window inside the committed tail) step.
        if self._rollout.commit(data, report.applied_ctrl, n):
            self.stats["committed"] += 1
        else:
            data.ctrl[:] = report.applied_ctrl
            mujoco.mj_step(self.model, data, nstep=n)
        report = report._stepped()  # as dataclasses.replace(report, stepped=True), without building the plan
        self.last_report = report
        return report

    def _account(self, r: StepReport) -> None:
        s = self.stats
        s["windows"] += 1
        s[r.verdict] += 1
        s["replaced"] += int(r.replaced)
        s["certify_us"] += r.certify_us

    def summary(self) -> dict[str, Any]:
        """Counts so far: windows, verdicts, replaced, fallback_uncertified, mean µs per window."""
        s = dict(self.stats)
        s["mean_certify_us"] = s["certify_us"] / s["windows"] if s["windows"] else 0.0
        return s

    # ----------------------------------------------------------------- logs
    def _open_log(self) -> Any:
        if self._log is not None or self._log_spec is None:
            return self._log
        spec = self._log_spec
        if isinstance(spec, (str, os.PathLike)):
            if self._log_options.get("key") == _KEY_WITHHELD:
                from monitor.errors import LogKeyError

                raise LogKeyError("this Gate is a pickled or deep-copied one whose log is signed with "
                                  "log_options['key']: the key is not copied with a Gate; make the gate "
                                  "anew with the key (or sign with $MONITOR_LOG_KEY_FILE)")
            from monitor.log._lock import claim_log_path
            from monitor.log.writer import MonitorLog  # lazy: mcap only when logging

            path, self._log_lock = claim_log_path(Path(spec))
            if path != Path(spec):
                warnings.warn(f"monitor.Gate: log {str(spec)!r} is being written by another gate; this gate "
                              f"writes {str(path)!r}", UserWarning, stacklevel=4)
            self._log_path = path
            meta = {"margin": self.margin, "epsilon": self.epsilon,
                    "predictor": self.predictor if isinstance(self.predictor, str) else "callable",
                    "on_violation": self.on_violation, "unsafe": self.unsafe, "frame_skip": self.frame_skip,
                    # the certify settings at open (ongoing rule, tolerances, budget, ...): request id 0;
                    # each certificate names its own (a setting changed later gets a new record)
                    "request": self.request.to_json(), **self._policy_metadata(),
                    _MODEL_EDITS_KEY: "logged",  # note_model before every window on an edited model
                    _ROLLOUTS_KEY: "logged"}  # every plan says where its rows come from (write_window)
            if self._predictor_label is not None:  # an adapter's predictor (SafetyGate predictor="plan")
                meta["predictor"] = self._predictor_label
            self._log = MonitorLog(path, model=self.model, metadata=meta, **self._log_options)
            self._log.__enter__()
            self._log_owned = True
        else:
            self._log = spec
            add = getattr(spec, "add_metadata", None)
            if callable(add):  # a user's MonitorLog: the pair policy of the windows this gate writes
                meta = self._policy_metadata()  # (requests: per certificate, by the log itself)
                if callable(getattr(spec, "note_model", None)):
                    meta[_MODEL_EDITS_KEY] = "logged"
                if getattr(spec, "logs_rollouts", False):
                    meta[_ROLLOUTS_KEY] = "logged"
                add(meta)
        return self._log

    def _policy_metadata(self) -> dict[str, Any]:
        """Run metadata that lets ``review --verify`` rebuild (and re-derive) this gate's pair set.

        ``pairs`` (mode or list), ``allowed_pairs`` (the candidate pairs the allowed-contact
        matrix and ``allow=`` took out, with reasons: never certified), ``hazards`` / ``allow``
        (the pattern items, JSON), ``allowed_mode`` (``"auto"``, ``"none"`` or ``"given"``: a
        user's matrix, whose reasons review cannot re-derive) and ``reference_qpos`` (the
        pose ``"auto"`` was resolved at; None = keyframe 0 / qpos0).
        """
        mode = "none" if self.allowed is None else (
            "auto" if isinstance(self.allowed, str) and self.allowed == "auto" else "given")
        ref = self.reference_qpos
        return {"applied_motions": "logged",  # every replaced action names the motion that ran
                "pairs": str(self.pairs), "allowed_pairs": [list(a) for a in self.scene.allowed_pairs],
                "hazards": _json_items(self.hazards), "allow": _json_items(self.allow),
                "allowed_mode": mode,
                "reference_qpos": None if ref is None else np.asarray(ref, float).tolist()}

    def _note_model(self) -> bool:
        """Log the model as the next window was certified on: an in-place edit since the last note.

        Called by :meth:`decide` once the proposal is certified (the first window, or the scene was
        rebuilt after a model edit) and again before a fallback's record, which a fallback callable
        may have edited the model for (red team 6): review re-derives each window on its own model.
        A log of rollouts is called every time (it records dynamics edits too; a few µs when the
        model is unchanged), and also before the rollout when the caller's ``cast`` may edit it.

        Returns:
            whether an edit was recorded.
        """
        log = self._open_log()
        if log is None:
            return False
        version = getattr(self._scene, "version", 0)
        # a log of rollouts also records dynamics edits (masses, gains, options: not in the scene
        # version) before every window, so that review re-simulates each on its model (a few µs)
        if version != self._noted_version or getattr(log, "logs_rollouts", False):
            self._noted_version = version
            note = getattr(log, "note_model", None)
            if callable(note):  # the log records what changed, so review re-derives on the model as certified
                return bool(note(self.model))
        return False

    def _write_log(self, r: StepReport, applied_plan: Any, plan: Any = None) -> None:
        """Log the step's windows; ``plan``: the proposal as :meth:`decide` made it (rows + rollout key)."""
        log = self._open_log()
        if log is None:
            return
        why = r.block_reason or None  # issue 13: proposal_violation / proposal_uncertain / brake_tail_...
        # where each window's rows come from (only for a log that records it: a MonitorLog)
        ro: dict[str, Any] = {}
        if getattr(log, "logs_rollouts", False):
            ro["rollout"] = _logged_rollout(plan)
        if not r.replaced:  # the window that ran is this one; it may commit a braking tail
            self._log_accepted = log.write_window(r.time, r.plan, r.certificate, r.proposed_ctrl,
                                                  r.applied_ctrl, False, reason=why, **ro)
            return
        fb = r.fallback_certificate
        if fb is None or not getattr(log, "logs_applied_motions", False):  # a log object of another kind
            log.write_window(r.time, r.plan, r.certificate, r.proposed_ctrl, r.applied_ctrl, True, reason=why,
                             **ro)
            if not r.fallback_certified and fb is not None:
                self._note_model()
                if ro:
                    ro["rollout"] = _logged_rollout(applied_plan)
                log.write_window(r.time, _plan_of(applied_plan), fb, r.applied_ctrl, r.applied_ctrl, True,
                                 reason=why, **ro)
            return
        self._write_applied(log, r, applied_plan, why, ro)

    def _write_applied(self, log: Any, r: StepReport, applied_plan: Any, why: str | None,
                       ro: dict[str, Any]) -> None:
        """Log a replaced step: its proposal, naming the record of the motion that ran.

        That record (``applied=``, see :data:`monitor.log.topics.APPLIED_MOTIONS_KEY`) is a fresh
        fallback's own window, or, for the committed brake (``decide`` reuses the committed tail's
        certificate object: ``applied_plan`` is None and the certificate *is* ``self._tail[1]``),
        the braking tail's plan and certificate, written at the first step braking on it and
        named again by the later ones.
        """
        fb = r.fallback_certificate
        nxt = log.windows  # the proposal's index; a new record gets the next one
        tail = self._tail
        if applied_plan is None and tail is not None and fb is tail[1]:
            rec = self._tail_record
            if rec is not None and rec[0] is fb:  # this tail is in the log already
                log.write_window(r.time, r.plan, r.certificate, r.proposed_ctrl, r.applied_ctrl, True,
                                 reason=why, applied_window=rec[1], **ro)
                return
            by = self._log_accepted
            applied = {"kind": "brake_tail", "covered_by": nxt + 1 if by is None else by}
            applied_plan = tail[0]  # a _Tail (its Plan below), or a Plan
            self._tail_record = (fb, nxt + 1)
        else:
            applied = {"kind": "fallback", "covered_by": nxt + 1}
        log.write_window(r.time, r.plan, r.certificate, r.proposed_ctrl, r.applied_ctrl, True, reason=why,
                         applied_window=nxt + 1, **ro)
        self._note_model()  # the fallback's model (an edit by a fallback callable)
        if ro:
            ro["rollout"] = _logged_rollout(applied_plan)
        log.write_window(r.time, _plan_of(applied_plan), fb, applied=applied, **ro)

    def close(self) -> None:
        """Finish the log if the gate opened it."""
        try:
            if self._log is not None and self._log_owned:
                self._log.__exit__(None, None, None)
        finally:
            self._log, self._log_owned = None, False
            if self._log_lock is not None:
                self._log_lock.close()  # releases the flock
                self._log_lock = None

    def __getstate__(self) -> dict[str, Any]:
        """Pickle state: all but the weak reference to the last checked ``MjData`` and the log's key.

        The signing key (``log_options["key"]``) is never written into a pickle or a deep copy; a
        copy that opens its log raises :class:`~monitor.errors.LogKeyError`.
        """
        state = self.__dict__.copy()
        state["_data_checked"] = None
        if isinstance(self._log_options.get("key"), bytes):
            state["_log_options"] = {**self._log_options, "key": _KEY_WITHHELD}
        return state

    def __enter__(self) -> Gate:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


_KEY_WITHHELD = "<log signing key withheld from a pickled or copied Gate>"
"""Stands for ``log_options["key"]`` in a pickled or deep-copied :class:`Gate` (see ``Gate.__getstate__``)."""


def _log_key(key: Any) -> Any:
    """``log_options["key"]`` checked when the gate is made (the log opens at the first window).

    Bytes of a valid key (:func:`monitor.log.sign.as_key`); None: the key file named by
    ``$MONITOR_LOG_KEY_FILE`` is checked now and read again when the log opens; False: unsigned.

    Raises:
        LogKeyError: an unusable key or key file.
    """
    from monitor.log import sign  # lazy: mcap only when logging

    if key is None:
        sign.key_from_env()
        return None
    if key is False:
        return False
    return sign.as_key(key, "log_options['key']")


_GATE_CERTIFY = Gate._certify
"""The :meth:`Gate._certify` this module defines (see :meth:`Gate._certify_is_own`)."""

__all__ = ["Gate", "StepReport", "Rollout", "hold_ctrl", "safety_info", "ON_VIOLATION", "UNSAFE"]
