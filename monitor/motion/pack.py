"""Pack a trajectory (:class:`monitor.Plan` or :class:`monitor.BodyMotion`) into flat arrays.

The :class:`MotionPack` is what the compiled kernels of :mod:`monitor.motion.kernel`
read: contiguous float64 / int64 arrays only, so the tuple is numba-typable and one
compiled specialisation serves every trajectory.

* A :class:`~monitor.Plan` is packed from its waypoints and its model's kinematic
  tree (read from the model as it is now, like ``Plan.body_poses`` does), with the
  plan's held mocap poses.
* A :class:`~monitor.BodyMotion` becomes a tree in which every body b >= 1 is a
  free-joint child of the world whose qpos is (position, quaternion) at each
  waypoint: lerp of the position and slerp of the quaternion, exactly BodyMotion's
  interpolation. The world (body 0) holds its constant pose.

The rounding scale (``tol[3]``) is computed once here, by the kernels, as
``Plan._scale`` defines it (the poses at the window's midpoint + reference points + the
whole-window bound: one bound pass, no FK at the waypoints; ``monitor.motion.plan``, "The
rounding scale").
"""

from __future__ import annotations

import operator
import sys
from typing import NamedTuple

import numpy as np
from numba import njit

from monitor._jit_cache import bind_caches, purge_if_changed
from monitor.errors import InvalidInputError, UnsupportedGeometryError
from monitor.motion import _kinematics as K_
from monitor.motion import kernel as KN
from monitor.motion.base import MotionBounds
from monitor.motion.bodymotion import BodyMotion
from monitor.tolerances import DEFAULT, Tolerances

purge_if_changed()  # before any cached kernel of this package loads (see monitor._jit_cache)

_FREE, _BALL, _SLIDE, _HINGE = 0, 1, 2, 3


class MotionPack(NamedTuple):
    """Flat arrays of one trajectory.

    K waypoints, nq coordinates, njnt joints, nbody bodies, nqt quaternion tracks.

    Attributes:
        times: (K,) waypoint times (s).
        qpos: (K, nq) waypoint joint positions (quaternions normalised).
        qpos0: (nq,) reference configuration (hinge/slide zero).
        jnt_type: (njnt,) MuJoCo joint type (0 free, 1 ball, 2 slide, 3 hinge).
        jnt_qposadr: (njnt,) first qpos column of each joint.
        jnt_pos: (njnt, 3) joint anchor in its body frame (m).
        jnt_axis: (njnt, 3) joint axis in its body frame (as in the model).
        jnt_axis_norm: (njnt,) norm of ``jnt_axis`` (1 for free/ball).
        jnt_track: (njnt,) quaternion track index of ball/free joints, else -1.
        body_parent: (nbody,) parent body (world: 0).
        body_jntadr, body_jntnum: (nbody,) first joint and joint count of each body.
        body_pos: (nbody, 3) body offset in the parent frame; absolute pose for body 0 and mocap bodies.
        body_quat: (nbody, 4) body orientation offset (unit; absolute for body 0 and mocap bodies).
        body_mocap: (nbody,) 1 where the packed pose is absolute and held (mocap).
        body_moving: (nbody,) 1 where some coordinate on the body's chain changes in the window.
        body_rotating: (nbody,) 1 where some rotational coordinate on the chain changes.
        ref_points: (nbody, 3) body-frame reference points of the bounds (m).
        qt_adr: (nqt,) first qpos column of each quaternion track.
        qt_target: (nqt, K-1, 4) segment end quaternions, sign-aligned with the start.
        qt_half: (nqt, K-1) half rotation angle of each segment (rad).
        qt_phi: (nqt, K-1) rotation angle of each segment (rad).
        qt_cum: (nqt, K) cumulative rotation path length at the waypoints (rad).
        qt_same: (nqt, K-1) 1 where a segment's end quaternions are bit-identical.
        tol: (6,) rel_pad, abs_pad, scale_pad, scale (m), joint magnitude, rotation path magnitude.
    """

    times: np.ndarray
    qpos: np.ndarray
    qpos0: np.ndarray
    jnt_type: np.ndarray
    jnt_qposadr: np.ndarray
    jnt_pos: np.ndarray
    jnt_axis: np.ndarray
    jnt_axis_norm: np.ndarray
    jnt_track: np.ndarray
    body_parent: np.ndarray
    body_jntadr: np.ndarray
    body_jntnum: np.ndarray
    body_pos: np.ndarray
    body_quat: np.ndarray
    body_mocap: np.ndarray
    body_moving: np.ndarray
    body_rotating: np.ndarray
    ref_points: np.ndarray
    qt_adr: np.ndarray
    qt_target: np.ndarray
    qt_half: np.ndarray
    qt_phi: np.ndarray
    qt_cum: np.ndarray
    qt_same: np.ndarray
    tol: np.ndarray

    @property
    def nbody(self) -> int:
        """Number of bodies (world included)."""
        return int(self.body_parent.shape[0])


def _f64(a: object, shape: tuple[int, ...] | None = None) -> np.ndarray:
    """Writable C-contiguous float64 (read-only arrays would compile a second specialisation)."""
    out = np.asarray(a, dtype=np.float64)
    if not (out.flags.c_contiguous and out.flags.writeable):
        out = np.array(out, dtype=np.float64, order="C")
    return out.reshape(shape) if shape is not None else out


def _i64(a: object) -> np.ndarray:
    out = np.asarray(a, dtype=np.int64).reshape(-1)
    if not (out.flags.c_contiguous and out.flags.writeable):
        out = np.array(out, dtype=np.int64, order="C")
    return out


STATIC_FIELDS = ("qpos0", "jnt_type", "jnt_qposadr", "jnt_pos", "jnt_axis", "jnt_axis_norm", "jnt_track",
                 "body_parent", "body_jntadr", "body_jntnum", "body_pos", "body_quat", "body_mocap",
                 "ref_points", "qt_adr")
"""The :class:`MotionPack` fields that depend on the model alone (for a Plan; mocap rows of
``body_pos`` / ``body_quat`` are the plan's held poses and are excluded by :func:`static_key`)."""


class _Static(NamedTuple):
    """The model-only part of a pack (shared by every pack of one model structure; never written).

    The :data:`STATIC_FIELDS` arrays are views, in that order and without gaps, of ONE float64
    buffer ``tree`` (the int64 fields are int64 views of its bytes), so the bytes of the whole
    kinematic tree are ``tree.tobytes()`` (:func:`static_key`). The rows of ``body_pos`` /
    ``body_quat`` of mocap bodies (b >= 1) are zero in ``tree``: a pack holds the plan's
    held mocap poses there (a copy of the two arrays).
    """

    qpos0: np.ndarray
    jnt_type: np.ndarray
    jnt_qposadr: np.ndarray
    jnt_pos: np.ndarray
    jnt_axis: np.ndarray
    jnt_axis_norm: np.ndarray
    jnt_track: np.ndarray
    body_parent: np.ndarray
    body_jntadr: np.ndarray
    body_jntnum: np.ndarray
    body_pos: np.ndarray
    body_quat: np.ndarray
    body_mocap: np.ndarray
    mocapid: np.ndarray
    ref_points: np.ndarray
    qt_adr: np.ndarray
    qpos0_mag: float
    mocap_rows: np.ndarray | None = None
    """(M,) bodies whose pack pose is the plan's held mocap pose (``mocapid >= 0``)."""
    quat_j: np.ndarray | None = None
    """(nqt,) ball / free joints, in track order."""
    tree: np.ndarray | None = None
    """(L,) float64: the buffer every :data:`STATIC_FIELDS` array is a view of (see above)."""
    shapes: tuple = ()
    """Shapes of the :data:`STATIC_FIELDS` arrays, in order (part of :func:`static_key`)."""
    key_memo: list | None = None
    """[(tree bytes, key)] of the last :func:`static_key` computed from this tree (a cache)."""
    keep_runs: tuple | None = None
    """(start, stop) row ranges, in order, of the bodies that are not in ``mocap_rows`` (their union
    is every other row; used by :func:`static_key` to compare a pack's pose rows without a copy)."""


def _tree_buffer(fields: list[tuple[np.ndarray, type]]) -> tuple[np.ndarray, list[np.ndarray]]:
    """One float64 buffer holding ``fields`` back to back; each returned as a view of its dtype."""
    n = sum(a.size for a, _ in fields)
    tree = np.zeros(n, dtype=np.float64)
    out, o = [], 0
    for a, dt in fields:
        v = tree[o:o + a.size].view(dt).reshape(a.shape)
        v[...] = a
        out.append(v)
        o += a.size
    return tree, out


def _static(qpos0: object, jnt_type: object, jnt_qposadr: object, jnt_pos: object, jnt_axis: object,
            body_parent: object, body_jntadr: object, body_jntnum: object, body_pos: object,
            body_quat: object, mocapid: object, ref_points: object, check_free: bool = True,
            world_identity: bool = False) -> _Static:
    jt = _i64(jnt_type)
    jadr = _i64(jnt_qposadr)
    jpos = _f64(np.array(jnt_pos, dtype=np.float64), (-1, 3))
    jaxis = _f64(np.array(jnt_axis, dtype=np.float64), (-1, 3))
    parent = _i64(body_parent)
    jntadr = _i64(body_jntadr)
    jntnum = _i64(body_jntnum)
    if check_free and (jt == _FREE).any():
        for b in range(parent.shape[0]):
            js = range(int(jntadr[b]), int(jntadr[b] + jntnum[b]))
            if any(jt[j] == _FREE for j in js) and (jntnum[b] != 1 or parent[b] != 0):
                raise UnsupportedGeometryError(
                    f"model body {b}: a free joint must be the only joint of a child of the world")
    quat_j = np.flatnonzero((jt == _FREE) | (jt == _BALL))
    jnt_track = np.full(jt.shape[0], -1, dtype=np.int64)
    jnt_track[quat_j] = np.arange(quat_j.shape[0])
    axis_norm = np.linalg.norm(jaxis, axis=-1) if jaxis.shape[0] else np.zeros(0)
    axis_norm = np.where((jt == _HINGE) | (jt == _SLIDE), axis_norm, 1.0).astype(np.float64)
    mid = _i64(mocapid)
    body_mocap = (mid >= 0).astype(np.int64)
    body_mocap[0] = 1
    q0 = _f64(np.array(qpos0, dtype=np.float64))
    bpos = _f64(np.array(body_pos, dtype=np.float64), (-1, 3))
    bquat = _f64(np.array(body_quat, dtype=np.float64), (-1, 4))
    if world_identity:      # MuJoCo's world body sits at the origin with identity orientation
        bpos[0] = 0.0
        bquat[0] = (1.0, 0.0, 0.0, 0.0)
    mocap_rows = np.flatnonzero(mid[1:] >= 0) + 1
    bpos[mocap_rows] = 0.0        # a pack holds the plan's mocap poses in these rows (static_key zeroes them)
    bquat[mocap_rows] = 0.0
    f, i = np.float64, np.int64
    fields = dict(qpos0=(q0, f), jnt_type=(jt, i), jnt_qposadr=(jadr, i), jnt_pos=(jpos, f),
                  jnt_axis=(jaxis, f), jnt_axis_norm=(_f64(axis_norm), f), jnt_track=(jnt_track, i),
                  body_parent=(parent, i), body_jntadr=(jntadr, i), body_jntnum=(jntnum, i),
                  body_pos=(bpos, f), body_quat=(bquat, f), body_mocap=(body_mocap, i),
                  ref_points=(_f64(np.array(ref_points, dtype=np.float64), (-1, 3)), f),
                  qt_adr=(_i64(jadr[quat_j] + np.where(jt[quat_j] == _FREE, 3, 0)), i))
    tree, views = _tree_buffer([fields[name] for name in STATIC_FIELDS])
    v = dict(zip(STATIC_FIELDS, views, strict=True))
    return _Static(**v, mocapid=mid, qpos0_mag=float(np.max(np.abs(q0), initial=0.0)), mocap_rows=mocap_rows,
                   quat_j=quat_j, tree=tree, shapes=tuple(a.shape for a in views), key_memo=[None],
                   keep_runs=_row_runs(mocap_rows, parent.shape[0]))


def _row_runs(skip: np.ndarray, n: int) -> tuple[tuple[int, int], ...]:
    """The (start, stop) ranges of rows 0..n-1 that are not in ``skip`` (sorted), in order."""
    runs, start = [], 0
    for r in skip.tolist():
        if r > start:
            runs.append((start, r))
        start = r + 1
    if start < n:
        runs.append((start, n))
    return tuple(runs)


_NO_TRACKS: dict[int, tuple[np.ndarray, ...]] = {}


def _track_arrays(tracks: list, K: int) -> tuple[np.ndarray, ...]:
    """(target, half, phi, cum, same) stacked from ``QuatTrack`` objects (bit-exact copies)."""
    n = len(tracks)
    if n == 0:   # zero-size arrays hold no data: one set per K, shared
        hit = _NO_TRACKS.get(K)
        if hit is None:
            hit = _NO_TRACKS[K] = (np.zeros((0, K - 1, 4)), np.zeros((0, K - 1)), np.zeros((0, K - 1)),
                                   np.zeros((0, K)), np.zeros((0, K - 1), dtype=np.int64))
        return hit
    return (np.ascontiguousarray(np.stack([tr.target for tr in tracks]), dtype=np.float64),
            np.ascontiguousarray(np.stack([tr.half for tr in tracks]), dtype=np.float64),
            np.ascontiguousarray(np.stack([tr.phi for tr in tracks]), dtype=np.float64),
            np.ascontiguousarray(np.stack([tr.cum for tr in tracks]), dtype=np.float64),
            np.ascontiguousarray(np.stack([tr.same for tr in tracks]), dtype=np.int64))


def _finish(st: _Static, times: np.ndarray, qpos: np.ndarray, body_pos: np.ndarray, body_quat: np.ndarray,
            tracks: list, tol: Tolerances) -> MotionPack:
    """Derived arrays (flags, magnitudes, rounding scale: one compiled call) and the pack.

    ``tracks``: the trajectory's own ``QuatTrack`` per quaternion track (order of ``st.qt_adr``).
    """
    K = qpos.shape[0]
    nbody = st.body_parent.shape[0]
    if len(tracks) != st.qt_adr.shape[0]:
        raise InvalidInputError(f"{len(tracks)} quaternion tracks for {st.qt_adr.shape[0]} ball/free joints")
    target, half, phi, cum, same = _track_arrays(tracks, K)
    pathmag = float(np.max(cum[:, -1], initial=0.0)) if cum.shape[0] else 0.0
    tol_arr = np.array([tol.rel_pad, tol.abs_pad, tol.scale_pad, 0.0, 0.0, pathmag])
    fields = (times, qpos, st.qpos0, st.jnt_type, st.jnt_qposadr, st.jnt_pos, st.jnt_axis,
              st.jnt_axis_norm, st.jnt_track, st.body_parent, st.body_jntadr, st.body_jntnum, body_pos,
              body_quat, st.body_mocap, np.empty(nbody, dtype=np.int64), np.empty(nbody, dtype=np.int64),
              st.ref_points, st.qt_adr, target, half, phi, cum, same, tol_arr)
    _derive_and_scale(st.qpos0_mag, *fields)
    return _new_pack(MotionPack, fields)  # = MotionPack(times=..., ..., tol=tol_arr), without keyword parsing


@njit(cache=True, error_model="numpy", no_cfunc_wrapper=True)
def _derive_and_scale(qpos0_mag, times, qpos, qpos0, jnt_type, jnt_qposadr, jnt_pos, jnt_axis, jnt_axis_norm,
                      jnt_track, body_parent, body_jntadr, body_jntnum, body_pos, body_quat, body_mocap,
                      body_moving, body_rotating, ref_points, qt_adr, qt_target, qt_half, qt_phi, qt_cum,
                      qt_same, tol) -> None:
    """Fill a pack's derived arrays in place, in one compiled call (issue 12: was two, plus numpy).

    Arguments: ``qpos0_mag`` (max |qpos0|) and the 25 :class:`MotionPack` arrays in field order
    (passed one by one: a numba call unboxes separate arrays about 2 us faster than the
    named tuple; the tuple is rebuilt here, the same arrays). Outputs: ``body_moving`` /
    ``body_rotating`` (nbody,) and ``tol[4]`` (max |qpos|) by :func:`monitor.motion.kernel.derive`,
    then ``tol[4] += qpos0_mag``, then, when some body moves, ``tol[3]`` (the rounding scale, m)
    by ``batch(pack, BATCH_SCALE, ...)`` with (1, nbody, ...) scratch; else it stays 0.
    ``tol[3]`` must be 0 and ``tol[5]`` (rotation path magnitude) set on entry. The same
    compiled functions and float64 operations in the same order as the former Python sequence
    (``derive``, ``+=``, ``moving.any()``, ``batch``): every byte of the pack is the same.
    """
    KN.derive(qpos, body_parent, body_mocap, body_jntadr, body_jntnum, jnt_type, jnt_qposadr, body_moving,
              body_rotating, tol)
    tol[KN.TOL_QMAG] += qpos0_mag
    nbody = body_parent.shape[0]
    for b in range(nbody):
        if body_moving[b] != 0:
            mp = MotionPack(times, qpos, qpos0, jnt_type, jnt_qposadr, jnt_pos, jnt_axis, jnt_axis_norm,
                            jnt_track, body_parent, body_jntadr, body_jntnum, body_pos, body_quat,
                            body_mocap, body_moving, body_rotating, ref_points, qt_adr, qt_target, qt_half,
                            qt_phi, qt_cum, qt_same, tol)
            z = np.zeros(1)
            tol[KN.TOL_SCALE] = KN.batch(mp, KN.BATCH_SCALE, z, z, np.empty((1, nbody, 3)),
                                         np.empty((1, nbody, 3, 3)), np.empty((1, nbody)),
                                         np.empty((1, nbody)))
            return


_new_pack = tuple.__new__


def _pack_body_motion(bm: BodyMotion) -> MotionPack:
    interp = getattr(bm, "interpolation", "lerp_slerp")
    if interp != "lerp_slerp":
        # the compiled kernels implement lerp + slerp only; packing a screw motion would
        # silently certify a different path
        raise UnsupportedGeometryError(
            f"pack_trajectory: BodyMotion interpolation {interp!r} is not supported by the compiled "
            "kernels (lerp_slerp only); use the Trajectory protocol (body_poses / motion_bounds)")
    pos = bm.pos
    quat = bm.quat
    K, nbody = pos.shape[0], pos.shape[1]
    nj = nbody - 1
    qpos = np.concatenate([pos[:, 1:], quat[:, 1:]], axis=2).reshape(K, 7 * nj)
    body_pos = np.zeros((nbody, 3))
    body_quat = np.zeros((nbody, 4))
    body_quat[:, 0] = 1.0
    body_pos[0] = pos[0, 0]
    body_quat[0] = quat[0, 0]
    jnt_axis = np.zeros((nj, 3))
    jnt_axis[:, 2] = 1.0
    st = _static(np.zeros(7 * nj), np.zeros(nj, dtype=np.int64), 7 * np.arange(nj), np.zeros((nj, 3)),
                 jnt_axis,
                 np.zeros(nbody, dtype=np.int64), np.concatenate([[0], np.arange(nj)]),
                 np.concatenate([[0], np.ones(nj, dtype=np.int64)]), body_pos, body_quat,
                 np.full(nbody, -1), bm.ref_points, check_free=False)
    tracks = getattr(bm, "_tracks", None)
    tracks = tracks[1:] if tracks is not None else [K_.QuatTrack(quat[:, b]) for b in range(1, nbody)]
    return _finish(st, _f64(bm.times), _f64(qpos), st.body_pos, st.body_quat, tracks, bm._tol)


def _plan_static(plan: object) -> _Static:
    """The model part of a Plan's pack, cached on the plan's model structure when it has one.

    ``Plan._st`` (plan.py's ``_ModelStructure``) is keyed by the bytes of every model
    array it reads, so a model edited in place gets a new one; its copies are the
    snapshot the plan was built on. Without it the model is read as it is now.
    """
    st = getattr(plan, "_st", None)
    if st is not None:
        hit = getattr(st, "_motion_pack_static", None)
        if hit is not None:
            return hit
        try:
            jnt = st.jnt
            jntadr = [js[0] if js else 0 for js in st.jnt_of_body]
            out = _static(jnt["qpos0"], jnt["type"], jnt["adr"], jnt["pos"], jnt["axis"], st.parent, jntadr,
                          [len(js) for js in st.jnt_of_body], st.body_pos, st.body_quat,
                          plan.model.body_mocapid, st.ref, world_identity=True)
        except (AttributeError, KeyError, TypeError):
            out = None
        if out is not None:
            st._motion_pack_static = out
            return out
    m = plan.model
    return _static(m.qpos0, m.jnt_type, m.jnt_qposadr, m.jnt_pos, m.jnt_axis, m.body_parentid, m.body_jntadr,
                   m.body_jntnum, m.body_pos, m.body_quat, m.body_mocapid, plan.ref_points,
                   world_identity=True)


def _pack_plan(plan: object) -> MotionPack:
    st = _plan_static(plan)
    body_pos = st.body_pos
    body_quat = st.body_quat
    mocap = st.mocap_rows
    if mocap.size:
        body_pos = body_pos.copy()
        body_quat = body_quat.copy()
        body_pos[mocap] = plan.mocap_pos[st.mocapid[mocap]]
        body_quat[mocap] = plan.mocap_quat[st.mocapid[mocap]]
    own = getattr(plan, "_quat_tracks", {})
    qpos = plan.qpos
    quat_j = st.quat_j
    # Plan builds each track from the view qpos[:, a:a + 4] of this very array: same arithmetic.
    tracks = [own[j] if j in own else K_.QuatTrack(qpos[:, a:a + 4])
              for j, a in zip(quat_j, st.qt_adr, strict=True)]
    return _finish(st, _f64(plan.times), _f64(qpos), body_pos, body_quat, tracks,
                   getattr(plan, "_tol", DEFAULT))


_get_static = operator.attrgetter(*STATIC_FIELDS)


def static_key(mp: MotionPack, st: _Static | None = None) -> bytes:
    """The model-only part of a pack (its kinematic tree) as a hashable key, mocap pose rows zeroed.

    The bytes of every :data:`STATIC_FIELDS` array of ``mp``, back to back in that order (the
    rows of ``body_pos`` / ``body_quat`` of mocap bodies b >= 1 zeroed), then the arrays'
    shapes. Two packs with equal keys compute the same forward kinematics for the same joint
    positions and mocap poses (the compiled FK reads nothing else of the model). The world's
    row (body 0) is kept.

    ``st``: the :class:`_Static` the pack was probably built from (optional). When every
    static array of ``mp`` IS that tree's view (identity) and the pack's ``body_pos`` /
    ``body_quat`` are the tree's or equal it outside the mocap rows, the key is the one
    computed field by field the last time ``st.tree`` held the same bytes (one
    ``tree.tobytes()`` and one comparison: every static array is a view of ``tree``, so an
    in-place edit of any of them is seen); otherwise (another or a modified pack, or a tree
    whose bytes changed) it is computed field by field. Same key either way.
    """
    if st is not None and st.tree is not None:
        arrs = _get_static(mp)
        mine = _get_static(st)
        same = True
        for k in () if all(map(operator.is_, arrs, mine)) else range(len(arrs)):
            if arrs[k] is not mine[k]:
                if k not in _POSE_IDX:
                    same = False
                    break
                a, b = arrs[k], mine[k]
                if a.shape != b.shape or a.dtype != b.dtype or st.keep_runs is None:
                    same = False
                    break
                # equal to the tree's rows outside the mocap rows (>= 1: the world has no mocap
                # id), compared run by run (basic slices: no copy of the pose arrays)
                for i, j in st.keep_runs:
                    if a[i:j].tobytes() != b[i:j].tobytes():
                        same = False
                        break
                if not same:
                    break
        if same:
            tree = st.tree.tobytes()
            last = st.key_memo[0]       # (tree bytes, key), replaced as one object (threads)
            if last is not None and last[0] == tree:
                return last[1]
            key = _field_key(mp)
            st.key_memo[0] = (tree, key)
            return key
    return _field_key(mp)


def _field_key(mp: MotionPack) -> bytes:
    """:func:`static_key` read field by field."""
    arrs = list(_get_static(mp))
    mocap = mp.body_mocap[1:] != 0
    if mocap.any():
        rows = np.flatnonzero(mocap) + 1
        for k in _POSE_IDX:
            arrs[k] = arrs[k].copy()
            arrs[k][rows] = 0.0
    return b"".join([a.tobytes() for a in arrs]) + b"|" + repr(tuple([a.shape for a in arrs])).encode()


_POSE_IDX = (STATIC_FIELDS.index("body_pos"), STATIC_FIELDS.index("body_quat"))


def probe_plan(plan: object, seed: int = 0, n: int = 4) -> object:
    """A Plan of ``plan``'s model through ``n`` random configurations, with random held mocap poses.

    The layout (joint types, qpos columns) comes from the plan's model structure snapshot
    (``plan._st``), not from a pack. Hinges: angles uniform in [-pi, pi]; slides and free
    positions: uniform in [-1, 1] m; ball / free quaternions and mocap orientations:
    uniform random unit quaternions; mocap positions uniform in [-1, 1] m. Seeded.
    """
    st = plan._st
    rng = np.random.default_rng(seed)
    q = np.empty((n, st.nq))
    for typ, a in zip(st.jtype_list, st.jadr_list, strict=True):
        if typ == _HINGE:
            q[:, a] = rng.uniform(-np.pi, np.pi, n)
        elif typ == _SLIDE:
            q[:, a] = rng.uniform(-1.0, 1.0, n)
        else:
            if typ == _FREE:
                q[:, a:a + 3] = rng.uniform(-1.0, 1.0, (n, 3))
                a += 3
            u = rng.normal(size=(n, 4))
            q[:, a:a + 4] = u / np.linalg.norm(u, axis=1, keepdims=True)
    u = rng.normal(size=(st.nmocap, 4))
    mq = u / np.linalg.norm(u, axis=1, keepdims=True) if st.nmocap else np.zeros((0, 4))
    mpos = rng.uniform(-1.0, 1.0, (st.nmocap, 3))
    return type(plan)(np.linspace(0.0, 1.0, n), q, plan.model, mocap_pos=mpos, mocap_quat=mq,
                      tolerances=getattr(plan, "_tol", DEFAULT))


def plan_data_agrees(plan: object, mp: MotionPack) -> bool:
    """The per-plan part of ``mp`` is the plan's own data, bit for bit.

    Checks: waypoint times and qpos; the quaternion tracks (segment targets, half angles,
    angles, cumulative path, same-flags: the plan's own ``QuatTrack`` objects, in joint
    order); the held mocap poses in the mocap rows of ``body_pos`` / ``body_quat``; and the
    moving / rotating flags against the plan's own (derived independently by ``Plan._setup``
    and by the compiled ``derive``). Each is one comparison of raw bytes (and shapes), the
    tracks' arrays joined in joint order. A few microseconds for a small tree.
    """
    st = plan._st
    if not (mp.times.tobytes() == plan.times.tobytes() and mp.qpos.shape == plan.qpos.shape
            and mp.qpos.tobytes() == plan.qpos.tobytes()):
        return False
    if not ((mp.body_moving != 0).tobytes() == plan._moving.tobytes()
            and (mp.body_rotating != 0).tobytes() == plan._rotating.tobytes()):
        return False
    qj = st.quat_joints
    if mp.qt_adr.tolist() != [a for _, a, _ in qj]:
        return False
    if qj:
        K = plan.times.shape[0]
        n = len(qj)
        if not (mp.qt_target.shape == (n, K - 1, 4) and mp.qt_half.shape == (n, K - 1)
                and mp.qt_phi.shape == (n, K - 1) and mp.qt_cum.shape == (n, K)
                and mp.qt_same.shape == (n, K - 1)):
            return False
        tracks = [plan._quat_tracks[j] for j, _, _ in qj]
        join = b"".join
        if not (mp.qt_target.tobytes() == join([tr.target.tobytes() for tr in tracks])
                and mp.qt_half.tobytes() == join([tr.half.tobytes() for tr in tracks])
                and mp.qt_phi.tobytes() == join([tr.phi.tobytes() for tr in tracks])
                and mp.qt_cum.tobytes() == join([tr.cum.tobytes() for tr in tracks])
                and (mp.qt_same != 0).tobytes() == join([tr.same.tobytes() for tr in tracks])):
            return False
    if st.nmocap:
        run = _mocap_run(st)
        if run is not None:     # rows r0..r1-1 hold mocap ids 0..M-1 in order: basic slices
            r0, r1 = run
            return (mp.body_pos[r0:r1].tobytes() == plan._mocap_pos.tobytes()
                    and mp.body_quat[r0:r1].tobytes() == plan._mocap_quat.tobytes())
        rows, mid = st.mocap_rows, st.mocap_ids   # the structure's own (its key holds body_mocapid)
        if not (mp.body_pos[rows].tobytes() == plan._mocap_pos[mid].tobytes()
                and mp.body_quat[rows].tobytes() == plan._mocap_quat[mid].tobytes()):
            return False
    return True


def _mocap_run(st: object) -> tuple[int, int] | None:
    """(r0, r1) when the structure's mocap rows are r0..r1-1 with mocap ids 0..M-1 in order, else None.

    Then ``body_pos[rows]`` == ``body_pos[r0:r1]`` and ``mocap_pos[ids]`` == ``mocap_pos``
    (all M rows), so :func:`plan_data_agrees` compares slices instead of fancy-indexed copies.
    Cached on the structure (``_ModelStructure``), whose ``mocap_rows`` / ``mocap_ids`` are
    read-only snapshots; the cache holds the two arrays it was derived from and is used only
    while the structure still holds those very objects.
    """
    rows, mid = st.mocap_rows, st.mocap_ids
    hit = getattr(st, "_pack_mocap_run", None)
    if hit is not None and hit[0] is rows and hit[1] is mid:
        return hit[2]
    m = int(mid.shape[0])
    run = None
    if m and rows.shape == (m,) and np.array_equal(mid, np.arange(m)) \
            and np.array_equal(rows, np.arange(int(rows[0]), int(rows[0]) + m)):
        run = (int(rows[0]), int(rows[0]) + m)
    st._pack_mocap_run = (rows, mid, run)
    return run


def pack_trajectory(traj: object) -> MotionPack:
    """Pack a :class:`monitor.Plan` or :class:`monitor.BodyMotion` for the compiled kernels.

    Exactly those classes: a subclass may override ``body_poses`` / ``motion_bounds`` (another
    motion through the same waypoints), which the pack, built from the waypoint arrays, would
    not follow (red team 10: a Plan subclass shifted through a wall was certified once a plain
    Plan of the model had verified the pack's tree). Subclasses take the general path.

    Raises:
        InvalidInputError: ``traj`` is neither (a subclass included).
        UnsupportedGeometryError: a free joint that is not the only joint of a world child, or a
            BodyMotion whose interpolation is not ``"lerp_slerp"`` (e.g. ``"screw"``).
    """
    if type(traj) is BodyMotion:
        return _pack_body_motion(traj)
    # A Plan can only exist once monitor.motion.plan is imported; looking it up here keeps this
    # module free of mujoco (the algorithmic core may import it) and costs nothing per call.
    plan_mod = sys.modules.get("monitor.motion.plan")
    if plan_mod is not None and type(traj) is plan_mod.Plan:
        return _pack_plan(traj)
    raise InvalidInputError(f"traj must be a Plan or a BodyMotion, got {type(traj).__name__}")


def poses_and_bounds(mp: MotionPack, t0: object, t1: object) -> tuple[np.ndarray, np.ndarray, MotionBounds]:
    """Midpoint poses and certified bounds for N sub-intervals, in one compiled call.

    A drop-in for ``traj.body_poses((t0 + t1) / 2)`` + ``traj.motion_bounds(t0, t1)``.

    Args:
        mp: the packed trajectory.
        t0: (N,) sub-interval starts (s), inside the window.
        t1: (N,) sub-interval ends (s), inside the window, t1 >= t0.

    Returns:
        positions (N, nbody, 3) m, rotations R_WB (N, nbody, 3, 3), and MotionBounds
        (trans (N, nbody) m, angle (N, nbody) rad).

    Raises:
        InvalidInputError: shapes, NaN, or a sub-interval outside the window.
    """
    window = (float(mp.times[0]), float(mp.times[-1]))
    a, b = K_.check_interval_arrays(t0, t1, window)
    N = a.shape[0]
    nbody = mp.nbody
    pos = np.empty((N, nbody, 3))
    rot = np.empty((N, nbody, 3, 3))
    trans = np.empty((N, nbody))
    angle = np.empty((N, nbody))
    KN.batch(mp, KN.BATCH_BOUNDS, np.ascontiguousarray(a), np.ascontiguousarray(b), pos, rot, trans, angle)
    return pos, rot, MotionBounds(t0=a, t1=b, trans=trans, angle=angle)


def body_poses(mp: MotionPack, times: object) -> tuple[np.ndarray, np.ndarray]:
    """World poses at ``times`` (T,): positions (T, nbody, 3) m, rotations (T, nbody, 3, 3)."""
    t = K_.check_times_in_window(times, (float(mp.times[0]), float(mp.times[-1])))
    pos = np.empty((t.shape[0], mp.nbody, 3))
    rot = np.empty((t.shape[0], mp.nbody, 3, 3))
    z = np.empty((1, 1))
    KN.batch(mp, KN.BATCH_POSES, np.ascontiguousarray(t), np.ascontiguousarray(t), pos, rot, z, z)
    return pos, rot


__all__ = ["MotionPack", "body_poses", "pack_trajectory", "plan_data_agrees", "poses_and_bounds",
           "probe_plan", "static_key"]


bind_caches(globals())  # numba ignores caches written under other kernel sources (see monitor._jit_cache)
