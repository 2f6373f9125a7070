"""MuJoCo's C ``mj_step`` / ``mj_getState`` / ``mj_setState`` / ``mj_copyData`` from numba nopython code.

Prototype only (issue 12, whole gated step). The functions are ``ctypes`` prototypes on
``libmujoco.so.*`` in the installed ``mujoco`` package directory: the same library the Python
bindings are linked against (one copy in the process: ``ldd _functions*.so`` resolves to it, and
``mju_user_error`` set here is the one the bindings see, see ``errors.py``). Pointers are passed as
``uint64`` (``MjModel._address`` / ``MjData._address``, ``ndarray.ctypes.data``): on x86-64 SysV an
``int64`` and a pointer travel in the same register, so the C side receives the pointer unchanged.

``physics(...)`` is the compiled core of one gated step's physics, the same sequence of C calls as
``monitor.gate.Rollout._window`` then ``Rollout.brake_rows`` (with ``hold_ctrl`` for the brake):

* window: ``mj_getState(data, INTEGRATION)`` (the key), ``mj_copyData(scratch <- data)``, ctrl into the
  scratch, ``nstep`` x (``mj_step``, ``mj_getState(TIME|QPOS)`` into ``win_rows[k]``), row 0 = the key's
  first ``1 + nq`` entries, ``mj_normalizeQuat`` on row 0's qpos; the unstable-simulation counters
  (BADQPOS..BADQACC) compared before / after;
* tail: ``mj_getState(scratch, INTEGRATION)`` -> ``mj_setState(tail scratch)``, the hold control from
  the window's end qpos (position-like actuators: ``-(b0 + b1 * gear * q) / gain``, others 0; clipped),
  then up to ``max_steps`` x (``mj_step``, ``mj_getState(TIME|QPOS|QVEL)`` into ``tail_rows[k]``),
  stopping at the first substep with every ``|qvel| <= vel_tol``.

Returns (tail rows used K, status): status 0 ok, 1 unstable window, 2 unstable tail (the gate then
raises / redoes the tail in its loop: the prototype just reports it).
"""
from __future__ import annotations

import ctypes
import glob
import os

import mujoco
import numba as nb
import numpy as np

_LIB_PATH = sorted(glob.glob(os.path.join(os.path.dirname(mujoco.__file__), "libmujoco.so*")))[0]
LIB = ctypes.CDLL(_LIB_PATH)
_u64, _i32 = ctypes.c_uint64, ctypes.c_int

c_mj_step = LIB.mj_step
c_mj_step.argtypes, c_mj_step.restype = [_u64, _u64], None
c_mj_getState = LIB.mj_getState
c_mj_getState.argtypes, c_mj_getState.restype = [_u64, _u64, _u64, _i32], None
c_mj_setState = LIB.mj_setState
c_mj_setState.argtypes, c_mj_setState.restype = [_u64, _u64, _u64, _i32], None
c_mj_copyData = LIB.mj_copyData
c_mj_copyData.argtypes, c_mj_copyData.restype = [_u64, _u64, _u64], _u64
c_mj_normalizeQuat = LIB.mj_normalizeQuat
c_mj_normalizeQuat.argtypes, c_mj_normalizeQuat.restype = [_u64, _u64], None

S = mujoco.mjtState
INTEGRATION = int(S.mjSTATE_INTEGRATION)
WINDOW_ROW = int(S.mjSTATE_TIME | S.mjSTATE_QPOS)
TAIL_ROW = int(S.mjSTATE_TIME | S.mjSTATE_QPOS | S.mjSTATE_QVEL)
UNSTABLE = slice(int(mujoco.mjtWarning.mjWARN_BADQPOS), int(mujoco.mjtWarning.mjWARN_BADQACC) + 1)


@nb.njit(cache=True)
def step_n(m_addr, d_addr, n):
    """``n`` plain ``mj_step`` calls (the ungated loop, compiled)."""
    for _ in range(n):
        c_mj_step(m_addr, d_addr)


@nb.njit(cache=True)
def physics(m_addr, d_addr, s_addr, t_addr, ctrl, s_ctrl, t_ctrl, s_warn, t_warn, nq, nstep,
            hold_a, hold_adr, gain0, bias0, bias1, gear0, lo, hi, limited, max_steps, vel_tol,
            key_state, end_state, win_rows, tail_rows):
    """One gated step's physics (window + braking tail) in one call; see the module docstring.

    Args (shapes): ctrl (nu,); s_ctrl / t_ctrl (nu,) views of the scratches' ``ctrl``; s_warn /
    t_warn (3,) int32 views of their unstable-warning counters; hold_a / hold_adr (k,) the
    position-like actuators and their joints' qpos addresses; gain0 .. hi (nu,) the model's value
    columns (live views); limited (nu,) bool; key_state / end_state (nstate,); win_rows
    (nstep + 1, 1 + nq); tail_rows (max_steps + 1, 1 + nq + nv).
    """
    c_mj_getState(m_addr, d_addr, key_state.ctypes.data, INTEGRATION)
    c_mj_copyData(s_addr, m_addr, d_addr)
    for i in range(ctrl.shape[0]):
        s_ctrl[i] = ctrl[i]
    ncol = 1 + nq
    for j in range(ncol):
        win_rows[0, j] = key_state[j]
    w0, w1, w2 = s_warn[0], s_warn[1], s_warn[2]
    rowbytes = win_rows.shape[1] * 8
    base = win_rows.ctypes.data
    for k in range(1, nstep + 1):
        c_mj_step(m_addr, s_addr)
        c_mj_getState(m_addr, s_addr, base + k * rowbytes, WINDOW_ROW)
    if s_warn[0] != w0 or s_warn[1] != w1 or s_warn[2] != w2:
        return 0, 1
    c_mj_normalizeQuat(m_addr, base + 8)
    # braking tail from the window's end
    c_mj_getState(m_addr, s_addr, end_state.ctypes.data, INTEGRATION)
    c_mj_setState(m_addr, t_addr, end_state.ctypes.data, INTEGRATION)
    nu = t_ctrl.shape[0]
    for i in range(nu):
        t_ctrl[i] = 0.0
    for j in range(hold_a.shape[0]):
        a = hold_a[j]
        if gain0[a] != 0.0 and bias1[a] != 0.0:
            length = gear0[a] * end_state[1 + hold_adr[j]]
            t_ctrl[a] = -(bias0[a] + bias1[a] * length) / gain0[a]
    for i in range(nu):
        if limited[i]:
            t_ctrl[i] = min(max(t_ctrl[i], lo[i]), hi[i])   # np.clip's result for finite bounds
    tcol = tail_rows.shape[1]
    nv = tcol - ncol
    for j in range(tcol):
        tail_rows[0, j] = end_state[j]
    t_warn[0] = 0
    t_warn[1] = 0
    t_warn[2] = 0
    tbase = tail_rows.ctypes.data
    end = max_steps
    for k in range(1, max_steps + 1):
        c_mj_step(m_addr, t_addr)
        c_mj_getState(m_addr, t_addr, tbase + k * tcol * 8, TAIL_ROW)
        vmax = 0.0
        for j in range(nv):
            v = abs(tail_rows[k, ncol + j])
            if v > vmax or v != v:
                vmax = v
        if vmax <= vel_tol:
            end = k
            break
    if t_warn[0] != 0 or t_warn[1] != 0 or t_warn[2] != 0:
        return end + 1, 2
    return end + 1, 0


class Physics:
    """Buffers and live views for :func:`physics` on one model (Python side, built once)."""

    def __init__(self, model, nstep, max_steps, vel_tol):
        from monitor.gate import _hold_plan
        self.m = model
        self.s = mujoco.MjData(model)
        self.t = mujoco.MjData(model)
        n = mujoco.mj_stateSize(model, mujoco.mjtState.mjSTATE_INTEGRATION)
        self.key, self.end = np.empty(n), np.empty(n)
        self.win = np.empty((nstep + 1, 1 + model.nq))
        self.tail = np.empty((max_steps + 1, 1 + model.nq + model.nv))
        a, adr, limited, whole, cols = _hold_plan(model)
        lim = np.ones(model.nu, bool) if limited is None else np.isin(np.arange(model.nu), limited)
        self.args_tail = (np.ascontiguousarray(a, np.int64), np.ascontiguousarray(adr, np.int64),
                          *cols, lim, int(max_steps), float(vel_tol))
        self.nstep = nstep
        self.views = (self.s.ctrl, self.t.ctrl, self.s.warning.number[UNSTABLE],
                      self.t.warning.number[UNSTABLE])

    def run_bindings(self, data, ctrl):
        """The same C calls as :func:`physics`, each through the Python bindings (errors -> FatalError).

        A lean Python loop (no rollout object, no bytes keys): what the physics costs when it stays on
        the bindings' error-safe path. The hold control and the stop test run in numpy / Python floats.
        """
        m, s, t = self.m, self.s, self.t
        key, end, win, tail = self.key, self.end, self.win, self.tail
        nq = m.nq
        mujoco.mj_getState(m, data, key, INTEGRATION)
        mujoco.mj_copyData(s, m, data)
        s_ctrl, t_ctrl, s_warn, t_warn = self.views
        s_ctrl[:] = ctrl
        win[0] = key[:1 + nq]
        w0 = s_warn.tobytes()
        for k in range(1, self.nstep + 1):
            mujoco.mj_step(m, s)
            mujoco.mj_getState(m, s, win[k], WINDOW_ROW)
        if s_warn.tobytes() != w0:
            return win, tail[:0], 1
        mujoco.mj_normalizeQuat(m, win[0, 1:])
        mujoco.mj_getState(m, s, end, INTEGRATION)
        mujoco.mj_setState(m, t, end, INTEGRATION)
        a, adr, gain0, bias0, bias1, gear0, lo, hi, lim, max_steps, vel_tol = self.args_tail
        t_ctrl[:] = 0.0
        for j in range(a.shape[0]):
            i = a[j]
            if gain0[i] != 0.0 and bias1[i] != 0.0:
                t_ctrl[i] = -(bias0[i] + bias1[i] * (gear0[i] * end[1 + adr[j]])) / gain0[i]
        np.clip(t_ctrl, lo, hi, out=t_ctrl, where=lim)
        tail[0] = end[:tail.shape[1]]
        t_warn[:] = 0
        k = 0
        for k in range(1, max_steps + 1):
            mujoco.mj_step(m, t)
            mujoco.mj_getState(m, t, tail[k], TAIL_ROW)
            if np.abs(tail[k, 1 + nq:]).max() <= vel_tol:
                break
        return win, tail[:k + 1], 2 if t_warn.any() else 0

    def run(self, data, ctrl):
        k, status = physics(self.m._address, data._address, self.s._address, self.t._address, ctrl,
                            *self.views, self.m.nq, self.nstep, *self.args_tail, self.key, self.end,
                            self.win, self.tail)
        return self.win, self.tail[:k], status
