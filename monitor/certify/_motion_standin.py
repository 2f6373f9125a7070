r"""Private stand-in for the compiled motion kernels of :mod:`monitor.motion.kernel` (issue 12).

Only :class:`monitor.BodyMotion` (piecewise lerp of the body origin + shortest-arc
slerp of the orientation, per body) is supported. The interface is the agreed one::

    pack_trajectory(traj) -> MotionPack                                    (Python)
    body_pose(mp, body, t, p_W_out (3,), R_WB_out (3, 3)) -> None          (njit)
    body_bound(mp, body, ta, tb, p_W_out (3,), R_WB_out (3, 3)) -> (trans, angle)   (njit)

so that :mod:`monitor.certify.kernels` swaps to the real module with one import.

Bound (the contract of :mod:`monitor.motion.base`, derivation as in
:mod:`monitor.motion.bodymotion`). On [ta, tb] with midpoint m:

* ``max_t |x(t) - x(m)|`` is attained at ta, tb or a waypoint inside (the norm of an
  affine function is convex on each linear piece);
* the rotation angle of ``R(t) R(m)^T`` is at most the slerp path length between m and
  t (geodesic distance on SO(3) <= length of any path), and the cumulative path length
  is monotone, so ``max(path(m) - path(ta), path(tb) - path(m))`` bounds it;
* ``trans = dx + chord(angle) |ref|`` (the reference point's displacement).

Rounding: dx is padded by ``rel_pad * max|x|``, the angle by ``rel_pad * (path + 1)``,
then both relatively and absolutely, exactly as :class:`BodyMotion` pads.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from monitor.errors import InvalidInputError
from monitor.tolerances import DEFAULT, Tolerances


class MotionPack(NamedTuple):
    """Flat arrays of a BodyMotion (numba-typable).

    Attributes:
        times: (K,) waypoint times (s).
        pos: (K, nbody, 3) waypoint origins (m).
        quat: (K, nbody, 4) unit waypoint quaternions (w, x, y, z).
        target: (K-1, nbody, 4) segment end quaternions, sign-aligned with the start.
        half: (K-1, nbody) half rotation angle of each segment (rad).
        cum: (K, nbody) cumulative rotation path length at the waypoints (rad).
        same: (K-1, nbody) int64, 1 where a segment's quaternions are identical.
        ref_points: (nbody, 3) body-frame reference points of the bounds (m).
        moving: (nbody,) int64, 1 where the body moves in the window.
        pos_mag: largest |coordinate| of the waypoint origins (m).
        scale: scene scale of the scale pad (m).
        rel_pad, abs_pad, scale_pad: rounding pads (``Tolerances``).
    """

    times: np.ndarray
    pos: np.ndarray
    quat: np.ndarray
    target: np.ndarray
    half: np.ndarray
    cum: np.ndarray
    same: np.ndarray
    ref_points: np.ndarray
    moving: np.ndarray
    pos_mag: float
    scale: float
    rel_pad: float
    abs_pad: float
    scale_pad: float


def pack_trajectory(traj, tolerances: Tolerances = DEFAULT) -> MotionPack:
    """Pack a :class:`monitor.BodyMotion` once into flat arrays.

    Raises:
        InvalidInputError: ``traj`` is not a BodyMotion (the stand-in supports no Plan).
    """
    from monitor.motion.bodymotion import BodyMotion

    if not isinstance(traj, BodyMotion):
        raise InvalidInputError(f"traj: the motion stand-in packs only BodyMotion, got {type(traj).__name__}")
    t = np.ascontiguousarray(traj.times, dtype=np.float64)
    p = np.ascontiguousarray(traj.pos, dtype=np.float64)
    q = np.ascontiguousarray(traj.quat, dtype=np.float64)
    a = q[:-1]
    b = q[1:].copy()
    flip = np.einsum("kbi,kbi->kb", a, b) < 0
    b[flip] *= -1.0
    half = 2.0 * np.arctan2(np.linalg.norm(b - a, axis=-1), np.linalg.norm(b + a, axis=-1))
    cum = np.concatenate([np.zeros((1, q.shape[1])), np.cumsum(2.0 * half, axis=0)], axis=0)
    same = np.all(a == b, axis=-1).astype(np.int64)
    ref = np.ascontiguousarray(traj.ref_points, dtype=np.float64)
    scale = float(np.max(np.linalg.norm(p, axis=-1), initial=0.0)) + 3.0 * float(
        np.max(np.linalg.norm(ref, axis=-1), initial=0.0))
    tol = tolerances
    return MotionPack(t, p, q, np.ascontiguousarray(b), np.ascontiguousarray(half), np.ascontiguousarray(cum),
                      same, ref, traj.moving_bodies().astype(np.int64),
                      float(np.max(np.abs(p), initial=0.0)), scale, float(tol.rel_pad), float(tol.abs_pad),
                      float(tol.scale_pad))


@njit(cache=True)
def _locate(times, t):
    """Segment index, local parameter in [0, 1], at_end flag (as ``Segments.locate``)."""
    K = times.shape[0]
    i = np.searchsorted(times, t, side="right") - 1
    if i < 0:
        i = 0
    if i > K - 2:
        i = K - 2
    s = (t - times[i]) / (times[i + 1] - times[i])
    if s < 0.0:
        s = 0.0
    if s > 1.0:
        s = 1.0
    return i, s, t >= times[K - 1]


@njit(cache=True)
def _sinc(x):
    """sin(x) / x, exact at 0."""
    if abs(x) < 1e-8:
        return 1.0 - x * x / 6.0
    return math.sin(x) / x


@njit(cache=True)
def _quat_mat(q, R):
    nq = math.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
    w, x, y, z = q[0] / nq, q[1] / nq, q[2] / nq, q[3] / nq
    R[0, 0] = 1 - 2 * (y * y + z * z)
    R[0, 1] = 2 * (x * y - w * z)
    R[0, 2] = 2 * (x * z + w * y)
    R[1, 0] = 2 * (x * y + w * z)
    R[1, 1] = 1 - 2 * (x * x + z * z)
    R[1, 2] = 2 * (y * z - w * x)
    R[2, 0] = 2 * (x * z - w * y)
    R[2, 1] = 2 * (y * z + w * x)
    R[2, 2] = 1 - 2 * (x * x + y * y)


@njit(cache=True)
def _pose_at(mp, body, i, s, at_end, p_out, R_out):
    K = mp.times.shape[0]
    q = np.empty(4)
    if at_end:
        for r in range(3):
            p_out[r] = mp.pos[K - 1, body, r]
        for r in range(4):
            q[r] = mp.quat[K - 1, body, r]
    else:
        for r in range(3):
            a = mp.pos[i, body, r]
            p_out[r] = a + s * (mp.pos[i + 1, body, r] - a)
        if mp.same[i, body] == 1 or s == 0.0:
            for r in range(4):
                q[r] = mp.quat[i, body, r]
        else:
            h = mp.half[i, body]
            den = _sinc(h)
            c0 = (1.0 - s) * _sinc((1.0 - s) * h) / den
            c1 = s * _sinc(s * h) / den
            for r in range(4):
                q[r] = c0 * mp.quat[i, body, r] + c1 * mp.target[i, body, r]
    _quat_mat(q, R_out)


@njit(cache=True)
def body_pose(mp, body, t, p_W_out, R_WB_out):
    """World pose of ``body`` at time ``t``: origin into p_W_out (3,), rotation into R_WB_out (3, 3)."""
    i, s, e = _locate(mp.times, t)
    _pose_at(mp, body, i, s, e, p_W_out, R_WB_out)


@njit(cache=True)
def _path(mp, body, t):
    i, s, e = _locate(mp.times, t)
    if e:
        return mp.cum[mp.times.shape[0] - 1, body]
    return mp.cum[i, body] + s * 2.0 * mp.half[i, body]


@njit(cache=True)
def body_bound(mp, body, ta, tb, p_W_out, R_WB_out):
    """Pose at m = (ta + tb) / 2 into the out arrays; returns (trans (m), angle (rad)).

    For all t in [ta, tb] and every body-frame point p:
    ``|X(t) p - X(m) p| <= trans + chord(angle) |p - ref_points[body]|`` (rounding padded).
    """
    m = 0.5 * (ta + tb)
    body_pose(mp, body, m, p_W_out, R_WB_out)
    if mp.moving[body] == 0:
        return 0.0, 0.0
    pa = np.empty(3)
    Rs = np.empty((3, 3))
    dx = 0.0
    for k in range(2):
        body_pose(mp, body, ta if k == 0 else tb, pa, Rs)
        d = 0.0
        for r in range(3):
            d += (pa[r] - p_W_out[r]) ** 2
        dx = max(dx, math.sqrt(d))
    for j in range(mp.times.shape[0]):
        if ta < mp.times[j] < tb:
            d = 0.0
            for r in range(3):
                d += (mp.pos[j, body, r] - p_W_out[r]) ** 2
            dx = max(dx, math.sqrt(d))
    dx = dx + mp.rel_pad * mp.pos_mag
    pm = _path(mp, body, m)
    th = max(pm - _path(mp, body, ta), _path(mp, body, tb) - pm)
    th = th + mp.rel_pad * (mp.cum[mp.times.shape[0] - 1, body] + 1.0)
    th = min(th * (1.0 + mp.rel_pad) + mp.abs_pad, math.pi)
    ref = mp.ref_points[body]
    rn = math.sqrt(ref[0] * ref[0] + ref[1] * ref[1] + ref[2] * ref[2])
    T = dx + 2.0 * math.sin(0.5 * th) * rn
    T = T * (1.0 + mp.rel_pad) + mp.abs_pad + mp.scale_pad * mp.scale
    return T, th


__all__ = ["MotionPack", "pack_trajectory", "body_pose", "body_bound"]
