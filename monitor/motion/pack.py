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
``Plan._scale`` defines it (waypoint origins + reference points + whole-window bound).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from monitor.errors import InvalidInputError, UnsupportedGeometryError
from monitor.motion import kernel as KN
from monitor.motion.base import MotionBounds
from monitor.motion.bodymotion import BodyMotion
from monitor.tolerances import DEFAULT, Tolerances

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
    out = np.ascontiguousarray(np.asarray(a, dtype=np.float64))
    return out.reshape(shape) if shape is not None else out


def _i64(a: object) -> np.ndarray:
    return np.ascontiguousarray(np.asarray(a, dtype=np.int64)).reshape(-1)


def _tracks(qpos: np.ndarray, adr: np.ndarray) -> tuple[np.ndarray, ...]:
    """Quaternion tracks of qpos columns adr[k]..adr[k]+3, with ``QuatTrack``'s formulas (vectorised)."""
    K = qpos.shape[0]
    n = adr.shape[0]
    if n == 0:
        return (np.zeros((0, K - 1, 4)), np.zeros((0, K - 1)), np.zeros((0, K - 1)), np.zeros((0, K)),
                np.zeros((0, K - 1), dtype=np.int64))
    cols = adr[:, None] + np.arange(4)[None, :]  # (n, 4)
    q = np.transpose(qpos[:, cols], (1, 0, 2))  # (n, K, 4)
    a = q[:, :-1]
    b = q[:, 1:].copy()
    flip = np.einsum("nkj,nkj->nk", a, b) < 0
    b[flip] *= -1.0
    half = 2.0 * np.arctan2(np.linalg.norm(b - a, axis=-1), np.linalg.norm(b + a, axis=-1))
    phi = 2.0 * half
    cum = np.concatenate([np.zeros((n, 1)), np.cumsum(phi, axis=1)], axis=1)
    same = np.all(a == b, axis=-1).astype(np.int64)
    return (np.ascontiguousarray(b), np.ascontiguousarray(half), np.ascontiguousarray(phi),
            np.ascontiguousarray(cum), np.ascontiguousarray(same))


def _finish(times: np.ndarray, qpos: np.ndarray, qpos0: np.ndarray, jnt_type: np.ndarray,
            jnt_qposadr: np.ndarray, jnt_pos: np.ndarray, jnt_axis: np.ndarray,
            body_parent: np.ndarray, body_jntadr: np.ndarray, body_jntnum: np.ndarray,
            body_pos: np.ndarray, body_quat: np.ndarray, body_mocap: np.ndarray,
            ref_points: np.ndarray, tol: Tolerances) -> MotionPack:
    """Derived arrays (tracks, flags, magnitudes, rounding scale) and the pack."""
    nbody = body_parent.shape[0]
    quat_j = np.flatnonzero((jnt_type == _FREE) | (jnt_type == _BALL))
    qt_adr = _i64(jnt_qposadr[quat_j] + np.where(jnt_type[quat_j] == _FREE, 3, 0))
    jnt_track = np.full(jnt_type.shape[0], -1, dtype=np.int64)
    jnt_track[quat_j] = np.arange(quat_j.shape[0])
    target, half, phi, cum, same = _tracks(qpos, qt_adr)
    axis_norm = np.linalg.norm(jnt_axis, axis=-1) if jnt_axis.shape[0] else np.zeros(0)
    axis_norm = np.where((jnt_type == _HINGE) | (jnt_type == _SLIDE), axis_norm, 1.0).astype(np.float64)
    moving = np.zeros(nbody, dtype=np.int64)
    rotating = np.zeros(nbody, dtype=np.int64)
    KN.motion_flags(qpos, body_parent, body_mocap, body_jntadr, body_jntnum, jnt_type, jnt_qposadr,
                    moving, rotating)
    qmag = float(np.max(np.abs(qpos), initial=0.0)) + float(np.max(np.abs(qpos0), initial=0.0))
    pathmag = float(np.max(cum[:, -1], initial=0.0)) if cum.shape[0] else 0.0
    tol_arr = np.array([tol.rel_pad, tol.abs_pad, tol.scale_pad, 0.0, qmag, pathmag], dtype=np.float64)
    mp = MotionPack(
        times=_f64(times), qpos=_f64(qpos), qpos0=_f64(qpos0), jnt_type=_i64(jnt_type),
        jnt_qposadr=_i64(jnt_qposadr), jnt_pos=_f64(jnt_pos, (-1, 3)), jnt_axis=_f64(jnt_axis, (-1, 3)),
        jnt_axis_norm=_f64(axis_norm), jnt_track=jnt_track, body_parent=_i64(body_parent),
        body_jntadr=_i64(body_jntadr), body_jntnum=_i64(body_jntnum), body_pos=_f64(body_pos, (-1, 3)),
        body_quat=_f64(body_quat, (-1, 4)), body_mocap=_i64(body_mocap), body_moving=moving,
        body_rotating=rotating, ref_points=_f64(ref_points, (-1, 3)), qt_adr=qt_adr, qt_target=target,
        qt_half=half, qt_phi=phi, qt_cum=cum, qt_same=same, tol=tol_arr)
    if moving.any():
        tol_arr[KN.TOL_SCALE] = KN.rounding_scale(mp)  # the pack shares tol_arr
    return mp


def _pack_body_motion(bm: BodyMotion) -> MotionPack:
    times = bm.times
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
    body_mocap = np.zeros(nbody, dtype=np.int64)
    body_mocap[0] = 1
    jnt_axis = np.zeros((nj, 3))
    jnt_axis[:, 2] = 1.0
    return _finish(times, qpos, np.zeros(7 * nj), np.zeros(nj, dtype=np.int64), 7 * np.arange(nj),
                   np.zeros((nj, 3)), jnt_axis, np.zeros(nbody, dtype=np.int64),
                   np.concatenate([[0], np.arange(nj)]), np.concatenate([[0], np.ones(nj, dtype=np.int64)]),
                   body_pos, body_quat, body_mocap, bm.ref_points, bm._tol)


def _pack_plan(plan: object) -> MotionPack:
    m = plan.model
    jnt_type = _i64(m.jnt_type)
    jnt_bodyid = _i64(m.jnt_bodyid)
    body_jntnum = _i64(m.body_jntnum)
    body_jntadr = _i64(m.body_jntadr)
    body_parent = _i64(m.body_parentid)
    free = np.flatnonzero(jnt_type == _FREE)
    for j in free:
        b = int(jnt_bodyid[j])
        if body_jntnum[b] != 1 or body_parent[b] != 0:
            raise UnsupportedGeometryError(
                f"model joint {j}: a free joint must be the only joint of a child of the world (body {b})")
    mocapid = _i64(m.body_mocapid)
    body_mocap = (mocapid >= 0).astype(np.int64)
    body_pos = np.array(m.body_pos, dtype=np.float64).reshape(-1, 3)
    body_quat = np.array(m.body_quat, dtype=np.float64).reshape(-1, 4)
    if m.nmocap:
        mb = np.flatnonzero(mocapid >= 0)
        body_pos[mb] = plan.mocap_pos[mocapid[mb]]
        body_quat[mb] = plan.mocap_quat[mocapid[mb]]
    body_mocap[0] = 1
    body_pos[0] = 0.0
    body_quat[0] = (1.0, 0.0, 0.0, 0.0)
    return _finish(plan.times, plan.qpos, np.asarray(m.qpos0, dtype=np.float64), jnt_type,
                   _i64(m.jnt_qposadr), np.asarray(m.jnt_pos, dtype=np.float64).reshape(-1, 3),
                   np.asarray(m.jnt_axis, dtype=np.float64).reshape(-1, 3), body_parent, body_jntadr,
                   body_jntnum, body_pos, body_quat, body_mocap, plan.ref_points,
                   getattr(plan, "_tol", DEFAULT))


def pack_trajectory(traj: object) -> MotionPack:
    """Pack a :class:`monitor.Plan` or :class:`monitor.BodyMotion` for the compiled kernels.

    Raises:
        InvalidInputError: ``traj`` is neither.
        UnsupportedGeometryError: a free joint that is not the only joint of a world child.
    """
    if isinstance(traj, BodyMotion):
        return _pack_body_motion(traj)
    from monitor.motion.plan import Plan  # imports mujoco; BodyMotion users need not

    if isinstance(traj, Plan):
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
    from monitor.motion import _kinematics as K

    window = (float(mp.times[0]), float(mp.times[-1]))
    a, b = K.check_interval_arrays(t0, t1, window)
    N = a.shape[0]
    nbody = mp.nbody
    pos = np.empty((N, nbody, 3))
    rot = np.empty((N, nbody, 3, 3))
    trans = np.empty((N, nbody))
    angle = np.empty((N, nbody))
    KN.batch_bounds(mp, np.ascontiguousarray(a), np.ascontiguousarray(b), pos, rot, trans, angle)
    return pos, rot, MotionBounds(t0=a, t1=b, trans=trans, angle=angle)


def body_poses(mp: MotionPack, times: object) -> tuple[np.ndarray, np.ndarray]:
    """World poses at ``times`` (T,): positions (T, nbody, 3) m, rotations (T, nbody, 3, 3)."""
    from monitor.motion import _kinematics as K

    t = K.check_times_in_window(times, (float(mp.times[0]), float(mp.times[-1])))
    pos = np.empty((t.shape[0], mp.nbody, 3))
    rot = np.empty((t.shape[0], mp.nbody, 3, 3))
    KN.batch_poses(mp, np.ascontiguousarray(t), pos, rot)
    return pos, rot


__all__ = ["MotionPack", "body_poses", "pack_trajectory", "poses_and_bounds"]
