"""Re-simulating a gate's windows from their logged rollouts (the ``rollout`` of a ``/monitor/plan``).

A gate whose rows come from its own MuJoCo rollout logs, with each such plan, what determines
those rows bit for bit on the logged model: the integration state the rollout started from
(``mj_getState(model, data, state, mjSTATE_INTEGRATION)``: time, qpos, qvel, act, history, warm
start, ctrl, applied forces, mocap poses, eq_active, userdata, plugin state) and the control held
over each run of substeps. ``mj_step`` is a deterministic function of that state and the model
(the gate's :class:`monitor.gate.Rollout` relies on it), so :func:`resimulate` on the attached
MJB model (with the logged in-place edits applied) gives the same rows, bit for bit, on the same
MuJoCo build. Payload (:func:`encode`; :data:`ENCODING`, little-endian float64, base64)::

    "source": "rollout",
    "rollout": {"encoding": "float64-le-base64", "state_spec": 32767, "state": "<b64 (nstate,)>",
                "segments": [{"ctrl": "<b64 (nu,)>", "substeps": n}, ...], "rows_from": r}

The plan's rows are the states after substeps ``r, r + 1, ...`` of the segments run one after
another (``r = 0``: row 0 is the start state itself, quaternions normalised as the gate does;
a braking tail, simulated after its window, has ``r`` = the window's substeps). ``"source":
"user"`` marks rows made by user code (a predictor callable, an adapter, an explicit Plan),
which nothing here can re-simulate.

Raw bytes (not JSON numbers) keep the state exact whatever it holds (``-0.0``, NaN in
``userdata``) and cost ~1 µs to encode per window.
"""

from __future__ import annotations

import base64
import binascii
import operator
from dataclasses import dataclass
from typing import Any

import numpy as np

from monitor.errors import InvalidInputError

ENCODING = "float64-le-base64"
"""How the state and controls of a ``rollout`` payload are stored."""
SOURCES = ("rollout", "user")
"""Values of a plan payload's ``source``."""
MAX_SUBSTEPS = 1_000_000
"""Upper bound on the substeps review re-simulates for one plan (a hostile payload cannot hang it)."""


def _b64(values: Any) -> str:
    raw = values if isinstance(values, bytes) else np.ascontiguousarray(values, dtype="<f8").tobytes()
    return base64.b64encode(raw).decode("ascii")


def _floats(text: Any, what: str) -> np.ndarray:
    if not isinstance(text, str):
        raise InvalidInputError(f"rollout {what} is not a base64 string")
    try:
        raw = base64.b64decode(text.encode("ascii"), validate=True)
    except (binascii.Error, UnicodeEncodeError, ValueError) as exc:
        raise InvalidInputError(f"rollout {what} is not valid base64") from exc
    if len(raw) % 8:
        raise InvalidInputError(f"rollout {what} is {len(raw)} bytes, not a whole number of float64")
    return np.frombuffer(raw, dtype="<f8").astype(np.float64)


def encode(rollout: Any, state_spec: int, nstate: int, nu: int) -> dict[str, Any]:
    """The ``rollout`` payload of ``(state, ((ctrl, substeps), ...), rows_from)`` (bytes or arrays).

    Raises:
        InvalidInputError: wrong sizes or counts (a state of another model, a ctrl of another nu).
    """
    try:
        state, segments, rows_from = rollout
        segs = [(c, int(n)) for c, n in segments]
    except (TypeError, ValueError) as exc:
        raise InvalidInputError(f"rollout must be 'user' or (state, ((ctrl, substeps), ...), rows_from), "
                                f"got {type(rollout).__name__}") from exc
    if len(state if isinstance(state, bytes) else np.ravel(state).tobytes()) != 8 * nstate:
        raise InvalidInputError(f"rollout state must be the model's {nstate} integration-state floats")
    total = sum(n for _, n in segs)
    if not segs or any(n < 1 for _, n in segs) or not 0 <= int(rows_from) <= total:
        raise InvalidInputError(f"rollout segments need substeps >= 1 and 0 <= rows_from <= {total}")
    out = []
    for c, n in segs:
        if len(c if isinstance(c, bytes) else np.ravel(c).tobytes()) != 8 * nu:
            raise InvalidInputError(f"rollout ctrl must be {nu} float64")
        out.append({"ctrl": _b64(c), "substeps": n})
    return {"encoding": ENCODING, "state_spec": int(state_spec), "state": _b64(state), "segments": out,
            "rows_from": int(rows_from)}


@dataclass(frozen=True)
class Rollout:
    """A decoded ``rollout`` payload.

    Attributes:
        state: (nstate,) integration state at the first substep.
        segments: ((ctrl (nu,), substeps), ...) in order.
        rows_from: substep of the plan's first row.
    """

    state: np.ndarray
    segments: tuple[tuple[np.ndarray, int], ...]
    rows_from: int

    @property
    def substeps(self) -> int:
        """Substeps simulated in all."""
        return sum(n for _, n in self.segments)


def decode(payload: Any, model: Any) -> Rollout:
    """Check and decode a ``rollout`` payload for ``model``.

    Raises:
        InvalidInputError: malformed, or sizes that are not ``model``'s (state, ctrl), or more
            than :data:`MAX_SUBSTEPS` substeps.
    """
    import mujoco

    if not isinstance(payload, dict):
        raise InvalidInputError("rollout is not an object")
    if payload.get("encoding") != ENCODING:
        raise InvalidInputError(f"rollout encoding {str(payload.get('encoding'))[:40]!r} is not {ENCODING}")
    spec = int(mujoco.mjtState.mjSTATE_INTEGRATION)
    if payload.get("state_spec") != spec:
        raise InvalidInputError(f"rollout state_spec {str(payload.get('state_spec'))[:20]} is not "
                                f"mjSTATE_INTEGRATION ({spec}) of this MuJoCo")
    state = _floats(payload.get("state"), "state")
    nstate = mujoco.mj_stateSize(model, spec)
    if state.size != nstate:
        raise InvalidInputError(f"rollout state has {state.size} floats, the model's integration state "
                                f"{nstate} (another model or MuJoCo version)")
    segs = payload.get("segments")
    if not isinstance(segs, list) or not segs:
        raise InvalidInputError("rollout segments is not a non-empty list")
    out = []
    for s in segs:
        n = s.get("substeps") if isinstance(s, dict) else None
        if not isinstance(n, int) or isinstance(n, bool) or n < 1:
            raise InvalidInputError(f"rollout segment substeps {str(n)[:20]} is not an integer >= 1")
        ctrl = _floats(s.get("ctrl"), "ctrl")
        if ctrl.size != model.nu:
            raise InvalidInputError(f"rollout ctrl has {ctrl.size} values, the model's nu is {model.nu}")
        out.append((ctrl, n))
    total = sum(n for _, n in out)
    r = payload.get("rows_from")
    if not isinstance(r, int) or isinstance(r, bool) or not 0 <= r <= total:
        raise InvalidInputError(f"rollout rows_from {str(r)[:20]} is not an integer in [0, {total}]")
    if total > MAX_SUBSTEPS:
        raise InvalidInputError(f"rollout has {total} substeps (more than {MAX_SUBSTEPS})")
    return Rollout(state, tuple(out), r)


def resimulate(model: Any, data: Any, ro: Rollout) -> tuple[Any, np.ndarray]:
    """The plan a gate's rollout of ``ro`` gives on ``model``, and the integration state at each row.

    Sets ``data``'s integration state to ``ro.state``, holds each segment's ctrl over its substeps
    (``mj_step``), and builds the :class:`monitor.Plan` exactly as the gate builds its window or
    braking tail (rows (time, qpos) from ``mj_getState``; a window's row 0 with its quaternions
    normalised; mocap poses held at the state's).

    Args:
        model: the logged model (the MJB attachment, with the logged edits applied).
        data: a scratch ``MjData`` of ``model`` (overwritten).
        ro: the decoded rollout.

    Returns:
        (plan, states (K, nstate)): the Plan and the integration state at each of its rows.
    """
    import mujoco

    from monitor.motion.plan import Plan

    spec = mujoco.mjtState.mjSTATE_INTEGRATION
    row_spec = mujoco.mjtState.mjSTATE_TIME | mujoco.mjtState.mjSTATE_QPOS
    nq = model.nq
    nrows = ro.substeps - ro.rows_from + 1
    rows = np.empty((nrows, 1 + nq))
    states = np.empty((nrows, ro.state.size))
    mujoco.mj_setState(model, data, ro.state, spec)
    k = 0
    if ro.rows_from == 0:
        rows[0] = ro.state[:1 + nq]
        mujoco.mj_normalizeQuat(model, rows[0, 1:])
        states[0] = ro.state
    for ctrl, n in ro.segments:
        data.ctrl[:] = ctrl
        for _ in range(n):
            mujoco.mj_step(model, data)
            k += 1
            if k >= ro.rows_from:
                i = k - ro.rows_from
                mujoco.mj_getState(model, data, rows[i], row_spec)
                mujoco.mj_getState(model, data, states[i], spec)
    plan = Plan._trusted(rows[:, 0].copy(), rows[:, 1:].copy(), model=model,
                         mocap_pos=np.array(data.mocap_pos), mocap_quat=np.array(data.mocap_quat))
    return plan, states


def first_difference(plan: Any, msg: dict[str, Any]) -> str | None:
    """Where the logged plan message ``msg`` differs from the re-simulated ``plan`` (bit for bit), or None."""
    try:
        times = np.asarray(msg["times"], dtype=np.float64)
        qpos = np.asarray(msg["qpos"], dtype=np.float64)
    except (KeyError, TypeError, ValueError) as exc:
        return f"logged rows unreadable ({type(exc).__name__})"
    if times.shape != plan.times.shape or qpos.shape != plan.qpos.shape:
        return (f"{len(times)} logged row(s), the re-simulation has {len(plan.times)} "
                f"(qpos {qpos.shape} vs {plan.qpos.shape})")
    differs = (times != plan.times) | (qpos != plan.qpos).any(axis=1)
    if differs.any():
        i = int(np.argmax(differs))
        dq = float(np.max(np.abs(qpos[i] - plan.qpos[i])))
        return (f"first differing row {i} of {len(times)} (t = {float(plan.times[i])!r} s; logged t = "
                f"{float(times[i])!r} s, max |qpos difference| {dq:.3g})")
    for key, width in (("mocap_pos", 3), ("mocap_quat", 4)):
        ref = getattr(plan, key)
        if msg.get(key) is None:
            if ref is not None and np.size(ref):
                return f"no logged {key}; the start state has {np.shape(ref)[0]} mocap body(ies)"
            continue
        try:
            got = np.asarray(msg[key], dtype=np.float64).reshape(-1, width)
        except (TypeError, ValueError):
            return f"logged {key} unreadable"
        if ref is None or got.shape != np.shape(ref) or (got != ref).any():
            return f"logged {key} is not the start state's"
    return None


def physics_index(model: Any) -> np.ndarray:
    """Positions in the integration-state vector of its physical part (``mjSTATE_FULLPHYSICS``).

    Time, qpos, qvel, act, history, plugin and plastic state: what the simulation carries from
    one window to the next (not the user inputs ctrl, forces, mocap, userdata nor the warm
    start, which user code may set between steps).
    """
    import mujoco

    S = mujoco.mjtState
    full = int(S.mjSTATE_FULLPHYSICS)
    idx = []
    at = 0
    for bit in range(int(S.mjNSTATE)):
        b = 1 << bit
        if not int(S.mjSTATE_INTEGRATION) & b:
            continue
        size = mujoco.mj_stateSize(model, b)
        if full & b:
            idx.extend(range(at, at + size))
        at += size
    return np.asarray(idx, dtype=np.int64)


_NOT_DYNAMICS = ("tex_", "bvh_", "mesh_", "skin_", "mat_", "light_", "cam_", "key_", "name", "paths", "text_",
                 "numeric_", "tuple_", "plugin_", "vis")
"""Prefixes of ``MjModel`` arrays that do not change a re-simulation (visual data, names, keyframes,
derived bounding volumes, mesh data other than what :data:`monitor.scene.SYNC_FIELDS` watches)."""
_NOT_DYNAMICS_SUFFIXES = ("_rgba", "_user")
"""... and suffixes (colours; user data arrays, which MuJoCo never reads)."""


def model_fields(model: Any) -> tuple[str, ...]:
    """Names of the ``MjModel`` arrays a re-simulation depends on.

    :data:`monitor.scene.SYNC_FIELDS` and every other non-empty array but those of
    :data:`_NOT_DYNAMICS` (masses, gains, damping, friction, solver parameters, ...); the
    options are :func:`option_fields`.
    """
    from monitor.scene import SYNC_FIELDS

    out = list(SYNC_FIELDS)
    for name in dir(model):
        if name.startswith(("_", *_NOT_DYNAMICS)) or name.endswith(_NOT_DYNAMICS_SUFFIXES) or name in out:
            continue
        v = getattr(model, name, None)
        if isinstance(v, np.ndarray) and v.size:
            out.append(name)
    return tuple(out)


def option_fields(model: Any) -> tuple[str, ...]:
    """Names of the ``mjOption`` fields (``model.opt``): all of them change a simulation."""
    opt = model.opt
    return tuple(n for n in dir(opt) if not n.startswith("_") and not callable(getattr(opt, n)))


class ModelWatch:
    """A quick test that no array of :func:`model_fields` and no option changed since a snapshot.

    The arrays lie in a few memory runs of the model's buffer (``monitor.scene._run_views``),
    each compared with one ``tobytes``; the options are read field by field (array options
    through views kept from construction). A few µs per call on the bundled models.
    """

    def __init__(self, model: Any) -> None:
        from monitor.scene import _run_views

        self.model = model
        arrays = [getattr(model, f) for f in model_fields(model)]
        self._runs = [(v, v.tobytes()) for v in _run_views([a for a in arrays if a.size])]
        opt = self._opt = model.opt
        names = option_fields(model)
        # the array options (gravity, wind, ..., o_friction) are views into the mjOption struct: one run
        self._opt_arrays = [(v, v.tobytes()) for v in _run_views(
            [v for v in (getattr(opt, n) for n in names) if isinstance(v, np.ndarray) and v.size])]
        scalars = [n for n in names if not isinstance(getattr(opt, n), np.ndarray)]
        self._opt_scalars = operator.attrgetter(*scalars) if scalars else (lambda o: ())
        self._opt_values = self._opt_scalars(opt)

    def unchanged(self) -> bool:
        """True if every watched byte and option equals the snapshot."""
        for v, b in self._runs:
            if v.tobytes() != b:
                return False
        for v, b in self._opt_arrays:
            if v.tobytes() != b:
                return False
        return self._opt_scalars(self._opt) == self._opt_values


__all__ = ["ENCODING", "SOURCES", "MAX_SUBSTEPS", "Rollout", "encode", "decode", "resimulate",
           "first_difference", "physics_index", "model_fields", "option_fields", "ModelWatch"]
